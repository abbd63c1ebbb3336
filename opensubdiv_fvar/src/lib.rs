//! Test-only: give an `opensubdiv_petite` topology descriptor a face-varying channel, so the
//! parity tests (`runtime/tests/integration/opensubdiv_parity.rs`, subtess's `opensubdiv`
//! feature) can evaluate OpenSubdiv's own face-varying limit surface. `opensubdiv-petite` 0.3
//! builds `Far::TopologyDescriptor` without channels and keeps the C++ struct in a private
//! field; this crate writes the channel into it through a pointer, after checking that the
//! wrapper is the C++ struct and nothing else. Without the `opensubdiv` feature it is empty.

#![deny(missing_docs)]

#[cfg(feature = "opensubdiv")]
mod channel {
    use std::marker::PhantomData;
    use std::mem::size_of;

    use opensubdiv_petite::far::TopologyDescriptor;
    use opensubdiv_petite_sys as sys;

    type RawDescriptor = sys::OpenSubdiv_v3_7_0_Far_TopologyDescriptor;
    type RawChannel = sys::OpenSubdiv_v3_7_0_Far_TopologyDescriptor_FVarChannel;

    /// One face-varying channel: `values` values, and the value of every face corner (in the
    /// descriptor's face-vertex order).
    pub struct FaceVaryingChannel<'a> {
        raw: RawChannel,
        _indices: PhantomData<&'a [i32]>,
    }

    impl<'a> FaceVaryingChannel<'a> {
        /// The channel of `values` values with corner values `indices`.
        pub fn new(values: usize, indices: &'a [i32]) -> Self {
            FaceVaryingChannel {
                raw: RawChannel {
                    numValues: i32::try_from(values).unwrap_or(i32::MAX),
                    valueIndices: indices.as_ptr(),
                },
                _indices: PhantomData,
            }
        }
    }

    /// Give `descriptor` (made for `vertices` vertices and `faces` faces) the one channel
    /// `channel`. Panics when the wrapper's layout is not the C++ struct's (checked through
    /// the sizes and the two counts it must hold), rather than write anywhere else.
    pub fn attach<'a>(
        descriptor: &mut TopologyDescriptor<'a>,
        channel: &'a FaceVaryingChannel<'a>,
        vertices: usize,
        faces: usize,
    ) {
        assert_eq!(
            size_of::<TopologyDescriptor<'a>>(),
            size_of::<RawDescriptor>(),
            "opensubdiv-petite's TopologyDescriptor is not Far::TopologyDescriptor alone"
        );
        let raw = (descriptor as *mut TopologyDescriptor<'a>).cast::<RawDescriptor>();
        // SAFETY: the wrapper holds the C++ descriptor and a zero-sized marker (same size,
        // checked above); the counts read back below confirm the struct sits at offset 0
        // before anything is written. The channel outlives the descriptor ('a).
        unsafe {
            assert_eq!(usize::try_from((*raw).numVertices).ok(), Some(vertices));
            assert_eq!(usize::try_from((*raw).numFaces).ok(), Some(faces));
            (*raw).numFVarChannels = 1;
            (*raw).fvarChannels = &channel.raw;
        }
    }
}

#[cfg(feature = "opensubdiv")]
pub use channel::{attach, FaceVaryingChannel};
