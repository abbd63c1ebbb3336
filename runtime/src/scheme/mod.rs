//! The scheme layer: for every subdivision scheme its refinement rules, the isolation of
//! irregular vertices by refinement, and the patches (which table stencils a face reads, and
//! from which control points). Above the mesh layer and the stencil tables, below the
//! tessellators.

pub mod butterfly;
pub mod catmull_clark;
pub mod loop_scheme;
pub mod patch;
pub mod region_isolate;
pub mod sqrt3;
pub mod stencil;
pub mod triangle;

use std::str::FromStr;

use table_format::SchemeId;

use crate::stencil_table::StencilTable;
use crate::RuntimeError;

/// The subdivision schemes a [`crate::Surface`] can be built with (each has embedded tables).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Scheme {
    /// Catmull–Clark: any polygons, closed or with boundary.
    CatmullClark,
    /// Loop (Warren's weights): triangles, closed or with boundary.
    Loop,
    /// The modified butterfly (interpolating): closed triangle meshes.
    Butterfly,
    /// Kobbelt's √3 (two steps as one ternary step): triangles, closed or with boundary
    /// (Kobbelt's boundary rules).
    Sqrt3,
}

impl Scheme {
    /// Every scheme, in the order the CLI lists them.
    pub const ALL: [Scheme; 4] = [
        Scheme::CatmullClark,
        Scheme::Loop,
        Scheme::Butterfly,
        Scheme::Sqrt3,
    ];

    /// The catalogue name (`catmull-clark`, `loop`, `butterfly`, `sqrt3`), as the CLI and the
    /// tables spell it.
    pub fn name(self) -> &'static str {
        self.table_scheme().name()
    }

    /// The cargo feature of `subtess` that embeds the scheme's default table: the catalogue
    /// name ([`Scheme::name`]).
    pub fn cargo_feature(self) -> &'static str {
        self.name()
    }

    /// Whether this build embeds the scheme's default table (its cargo feature is enabled);
    /// without it [`Scheme::default_table`] returns [`RuntimeError::NotEmbedded`].
    pub fn is_embedded(self) -> bool {
        match self {
            Scheme::CatmullClark => cfg!(feature = "catmull-clark"),
            Scheme::Loop => cfg!(feature = "loop"),
            Scheme::Butterfly => cfg!(feature = "butterfly"),
            Scheme::Sqrt3 => cfg!(feature = "sqrt3"),
        }
    }

    /// Whether the scheme subdivides triangles (the triangle dual grid tessellates it).
    pub fn is_triangle(self) -> bool {
        self != Scheme::CatmullClark
    }

    /// The scheme id its tables carry.
    pub fn table_scheme(self) -> SchemeId {
        match self {
            Scheme::CatmullClark => SchemeId::CatmullClark,
            Scheme::Loop => SchemeId::Loop,
            Scheme::Butterfly => SchemeId::Butterfly,
            Scheme::Sqrt3 => SchemeId::Sqrt3,
        }
    }

    /// The embedded default table for a mesh with boundary rule `boundary` (Catmull–Clark has
    /// a pinned-corner companion for "edge and corner"); [`RuntimeError::NotEmbedded`] when
    /// this build does not embed it ([`Scheme::is_embedded`]).
    pub fn default_table(
        self,
        boundary: schemes::BoundaryMode,
    ) -> Result<StencilTable, RuntimeError> {
        match self {
            Scheme::CatmullClark => StencilTable::default_for(boundary),
            Scheme::Loop => StencilTable::default_loop(),
            Scheme::Butterfly => StencilTable::default_butterfly(),
            Scheme::Sqrt3 => StencilTable::default_sqrt3(),
        }
    }

    /// One whole-mesh subdivision step by this scheme's rules (two steps for √3, its ternary
    /// step): for reaching a face count in benchmarks and for whole-mesh references.
    pub fn refine(self, mesh: &crate::mesh::Mesh) -> Result<crate::mesh::Mesh, RuntimeError> {
        use crate::scheme::triangle::region_patch::RegionScheme;
        match self {
            Scheme::CatmullClark => Ok(catmull_clark::refine::refine(mesh).mesh),
            Scheme::Loop => Ok(loop_scheme::refine::loop_refine(mesh)?.mesh),
            Scheme::Butterfly => RegionScheme::Butterfly.refine(mesh),
            Scheme::Sqrt3 => RegionScheme::Sqrt3.refine(mesh),
        }
    }

    /// Refuse a table made for another scheme: its stencils have another layout or another
    /// limit surface, and would be read silently wrong.
    pub fn check_table(self, table: &StencilTable) -> Result<(), RuntimeError> {
        let found = table.index().meta.scheme;
        if found == self.table_scheme() {
            Ok(())
        } else {
            Err(RuntimeError::InvalidParameter {
                name: "table".to_owned(),
                reason: format!(
                    "it holds {} stencils, but the surface is {}",
                    found.name(),
                    self.name()
                ),
            })
        }
    }
}

impl std::fmt::Display for Scheme {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Scheme {
    type Err = RuntimeError;

    /// A scheme by its catalogue name; a catalogued scheme without a runtime table is named
    /// as such.
    fn from_str(name: &str) -> Result<Self, Self::Err> {
        if let Some(scheme) = Scheme::ALL.into_iter().find(|s| s.name() == name) {
            return Ok(scheme);
        }
        if schemes::triangle::TRIANGLE_SCHEME_NAMES.contains(&name)
            || schemes::quad::QUAD_SCHEME_NAMES.contains(&name)
        {
            return Err(RuntimeError::Unsupported(format!(
                "scheme `{name}`: no table for this scheme yet (the runtime has tables for catmull-clark, loop, butterfly and sqrt3)"
            )));
        }
        Err(RuntimeError::InvalidParameter {
            name: format!("scheme `{name}`"),
            reason: "not a scheme; catmull-clark, loop, butterfly or sqrt3".to_owned(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every scheme's cargo feature is declared in this crate's manifest, forwards to the
    /// tables crate's feature of the same name, and is among the defaults.
    #[test]
    fn every_scheme_has_its_cargo_feature() {
        let manifest = include_str!("../../Cargo.toml");
        let default = manifest
            .lines()
            .find(|line| line.starts_with("default = ["))
            .expect("a default feature list");
        for scheme in Scheme::ALL {
            let feature = scheme.cargo_feature();
            let forward = format!("\n{feature} = [\"subtess-tables/{feature}\"]\n");
            assert!(manifest.contains(&forward), "no feature line {forward:?}");
            assert!(default.contains(&format!("\"{feature}\"")), "{default}");
        }
    }

    /// A scheme's default table loads exactly when its feature is on (true of any feature
    /// set; all four by default); otherwise the error names the scheme and the feature.
    #[test]
    fn default_tables_follow_the_features() {
        for scheme in Scheme::ALL {
            match scheme.default_table(schemes::BoundaryMode::EdgeAndCorner) {
                Ok(table) => {
                    assert!(scheme.is_embedded(), "{scheme}");
                    assert_eq!(table.index().meta.scheme, scheme.table_scheme());
                }
                Err(RuntimeError::NotEmbedded { scheme: missing }) => {
                    assert!(!scheme.is_embedded(), "{scheme}");
                    assert_eq!(missing, scheme);
                }
                Err(e) => panic!("{scheme}: {e}"),
            }
        }
    }

    /// The message a build without a scheme's table gives (the CLI prints it as is).
    #[test]
    fn a_missing_table_names_its_feature() {
        let message = |scheme| RuntimeError::NotEmbedded { scheme }.to_string();
        assert_eq!(
            message(Scheme::Loop),
            "the loop table is not embedded in this build: enable subtess's cargo feature \
             `loop`, or give a table file (the CLI's --table FILE)"
        );
        assert!(message(Scheme::CatmullClark).contains("cargo feature `catmull-clark`"));
        assert!(message(Scheme::Sqrt3).starts_with("the sqrt3 table is not embedded"));
    }
}
