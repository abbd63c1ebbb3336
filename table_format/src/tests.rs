//! Every way a table can be broken gets its own error, never a panic.

use proptest::prelude::*;

use super::*;

fn key(kind: StencilKind, points: PointSet, faces: u32, n: u32) -> SectionKey {
    SectionKey {
        kind,
        points,
        boundary: false,
        feature: Feature::None,
        faces,
        sector: 0,
        n,
    }
}

fn sample() -> Vec<u8> {
    let meta = TableMeta {
        scheme: SchemeId::CatmullClark,
        precision: Precision::F32,
        corners: false,
    };
    let mut sections = Vec::new();
    for n in 1..=3u32 {
        for (points, count) in [
            (PointSet::Primal, (n + 1) * (n + 1)),
            (PointSet::Dual, n * n),
        ] {
            let weights = (0..count * 14).map(|i| f64::from(i) / 7.0).collect();
            sections.push((key(StencilKind::Position, points, 3, n), 14, weights));
        }
    }
    encode(meta, &sections).expect("valid")
}

fn parse(bytes: &[u8]) -> Result<(), TableError> {
    let aligned = AlignedBytes::from_slice(bytes);
    let table = Table::parse(aligned.as_bytes())?;
    for e in table.entries.clone() {
        table.weights_f32(&e.key)?;
    }
    Ok(())
}

/// Re-seal a modified file with a correct checksum, to reach the checks behind it.
fn reseal(bytes: &mut [u8]) {
    let c = checksum(bytes);
    bytes[CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8].copy_from_slice(&c.to_le_bytes());
}

#[test]
fn round_trip() {
    let bytes = sample();
    let aligned = AlignedBytes::from_slice(&bytes);
    let table = Table::parse(aligned.as_bytes()).expect("valid");
    let w = table
        .weights_f32(&key(StencilKind::Position, PointSet::Dual, 3, 2))
        .expect("present");
    assert_eq!(w.len(), 4 * 14);
    assert_eq!(w[7], 1.0);
    assert_eq!(
        table.coverage(),
        "interior valences 3, no boundary vertices, n = 1..=3"
    );
    // Byte-for-byte deterministic, whatever the order sections are given in.
    assert_eq!(bytes, sample());
    // Version 5, and the stored checksum is the one over every byte but its own.
    assert_eq!(table.version, 5);
    assert_eq!(table.checksum, checksum(&bytes));
    assert_eq!(u64_at(&bytes, CHECKSUM_OFFSET), table.checksum);
    // Streamed over the two runs, equal to the one-shot hash of the runs laid end to end
    // (docs/table-format.md).
    let runs = [&bytes[..CHECKSUM_OFFSET], &bytes[CHECKSUM_OFFSET + 8..]].concat();
    assert_eq!(table.checksum, xxhash_rust::xxh3::xxh3_64(&runs));
}

#[test]
fn wrong_magic() {
    let mut b = sample();
    b[0] = b'X';
    assert!(matches!(parse(&b), Err(TableError::BadMagic { .. })));
    assert!(matches!(parse(b"PNG"), Err(TableError::BadMagic { .. })));
}

/// Issue 20: the header alone decides whether a file is worth reading. A declared size above
/// [`MAX_FILE_SIZE`] or one that disagrees with the file's length is refused from the first
/// [`HEADER_SIZE`] bytes (a reader checks these before it reads a 100 GB file).
#[test]
fn header_checked_against_the_file_length_and_the_limit() {
    let b = sample();
    let head = &b[..HEADER_SIZE];
    assert_eq!(check_header(head, b.len() as u64), Ok(()));
    let huge = 100u64 << 30;
    let e = check_header(head, huge).expect_err("longer than declared");
    assert!(
        matches!(
            e,
            TableError::BadField {
                field: "file size",
                ..
            }
        ),
        "{e}"
    );
    let e = check_header(head, 10).expect_err("shorter than declared");
    assert!(matches!(e, TableError::Truncated { .. }), "{e}");
    let mut big = head.to_vec();
    big[32..40].copy_from_slice(&huge.to_le_bytes());
    let e = check_header(&big, huge).expect_err("over the limit");
    assert_eq!(e, TableError::TooLarge { declared: huge });
    assert!(e.to_string().contains("4 GiB"), "{e}");
    assert!(matches!(
        check_header(&[0u8; 64], huge),
        Err(TableError::BadMagic { .. })
    ));
}

#[test]
fn newer_and_older_versions() {
    for v in [0u32, VERSION - 1, VERSION + 1, 99] {
        let mut b = sample();
        b[8..12].copy_from_slice(&v.to_le_bytes());
        assert_eq!(
            parse(&b),
            Err(TableError::UnsupportedVersion {
                found: v,
                supported: VERSION
            })
        );
    }
}

#[test]
fn big_endian_mark() {
    let mut b = sample();
    b[12..16].copy_from_slice(&ENDIAN_MARK.to_be_bytes());
    assert!(matches!(parse(&b), Err(TableError::Endianness { .. })));
}

#[test]
fn truncated() {
    let b = sample();
    for cut in [10, HEADER_SIZE - 1, HEADER_SIZE + 5, b.len() - 1] {
        let e = parse(&b[..cut]).expect_err("truncated");
        assert!(
            matches!(e, TableError::Truncated { .. }),
            "cut at {cut}: {e}"
        );
    }
}

#[test]
fn flipped_byte_fails_the_checksum() {
    let b = sample();
    for at in [HEADER_SIZE, HEADER_SIZE + 17, b.len() / 2, b.len() - 1] {
        let mut c = b.clone();
        c[at] ^= 0x10;
        assert!(
            matches!(parse(&c), Err(TableError::Checksum { .. })),
            "byte {at}"
        );
    }
}

/// Issue 18 (the hole issue 20's fuzzing found): every byte of the file but the checksum's own
/// is hashed since format version 3. Each byte of the header and the index, and every 7th byte
/// after (padding and weights), is changed two ways; each change must be an `Err` (never a
/// panic, never a table read as something else), and `Checksum` for every byte that the header
/// checks before the checksum (magic, version, endianness mark, header size, file size) do not
/// catch first.
#[test]
fn every_single_byte_change_is_refused() {
    let b = sample();
    let index_end = HEADER_SIZE + ENTRY_SIZE * u32_at(&b, 20) as usize;
    let positions = (0..index_end).chain((index_end..b.len()).step_by(7));
    let mut checked = 0;
    for at in positions {
        for xor in [0x01u8, 0xff] {
            let mut c = b.clone();
            c[at] ^= xor;
            let e = parse(&c).expect_err(&format!("byte {at} ^ {xor:#04x} was read"));
            let by_field_check = match at {
                0..=7 => matches!(e, TableError::BadMagic { .. }),
                8..=11 => matches!(e, TableError::UnsupportedVersion { .. }),
                12..=15 => matches!(e, TableError::Endianness { .. }),
                16..=19 => matches!(
                    e,
                    TableError::BadField {
                        field: "header size",
                        ..
                    }
                ),
                32..=39 => matches!(
                    e,
                    TableError::Truncated { .. }
                        | TableError::TooLarge { .. }
                        | TableError::BadField {
                            field: "file size",
                            ..
                        }
                ),
                _ => matches!(e, TableError::Checksum { .. }),
            };
            assert!(by_field_check, "byte {at} ^ {xor:#04x}: {e}");
            checked += 1;
        }
    }
    // 64 header bytes and 6 entries of 40 bytes, both ways, and the sample after them.
    assert!(checked > 2 * (64 + 6 * 40), "{checked}");
}

/// The three changes docs/reliability.md wrote up for version 2, each now refused by the
/// checksum: the boundary-mode flag (read silently as the other mode), the section count
/// (sections dropped) and the scheme id (caught only by `Surface::with_table`).
#[test]
fn header_fields_are_checksummed() {
    let b = sample();
    let mut corners = b.clone();
    corners[56] = 1;
    let mut fewer = b.clone();
    fewer[20..24].copy_from_slice(&2u32.to_le_bytes());
    let mut scheme = b.clone();
    scheme[52..56].copy_from_slice(&(SchemeId::SwNonpolyQuad as u32).to_le_bytes());
    for (what, c) in [("corners", corners), ("count", fewer), ("scheme", scheme)] {
        let e = parse(&c).expect_err(what);
        assert!(matches!(e, TableError::Checksum { .. }), "{what}: {e}");
        assert!(e.to_string().contains("header"), "{what}: {e}");
    }
    // Re-sealed, the same changes read as what they say (the checksum is what refuses them).
    let mut corners = b.clone();
    corners[56] = 1;
    reseal(&mut corners);
    let aligned = AlignedBytes::from_slice(&corners);
    assert!(
        Table::parse(aligned.as_bytes())
            .expect("re-sealed")
            .meta
            .corners
    );
}

/// A table of an older format version names its version and how to regenerate it; a newer
/// one says so too.
#[test]
fn older_versions_name_themselves_and_the_command() {
    // 4: the last version without the feature byte (its byte 3 was reserved, always 0).
    for old in [1u32, 2, 4] {
        let mut b = sample();
        b[8..12].copy_from_slice(&old.to_le_bytes());
        let e = parse(&b).expect_err("an older version");
        assert_eq!(
            e,
            TableError::UnsupportedVersion {
                found: old,
                supported: VERSION
            }
        );
        let message = e.to_string();
        assert!(
            message.contains(&format!("version {old} ")) && message.contains("stencilgen tables"),
            "{message}"
        );
        assert!(message.contains("older"), "{message}");
    }
    let mut b = sample();
    b[8..12].copy_from_slice(&(VERSION + 1).to_le_bytes());
    let message = parse(&b).expect_err("a newer version").to_string();
    assert!(message.contains("newer"), "{message}");
}

/// A dart section's key round-trips with its feature in index byte 3 (0 none, 1 dart) and sorts
/// after the smooth patches of its valence; a feature byte the format does not define, or a
/// dart on a boundary key, is refused by the reader (behind a valid checksum) and the writer.
#[test]
fn dart_keys_round_trip_and_bad_feature_bytes_are_refused() {
    let meta = TableMeta {
        scheme: SchemeId::CatmullClark,
        precision: Precision::F32,
        corners: false,
    };
    let smooth = key(StencilKind::Position, PointSet::Dual, 3, 1);
    let dart = SectionKey {
        feature: Feature::Dart,
        sector: 2,
        ..smooth
    };
    let bytes = encode(
        meta,
        &[(dart, 14, vec![0.5; 14]), (smooth, 14, vec![0.25; 14])],
    )
    .expect("valid");
    let aligned = AlignedBytes::from_slice(&bytes);
    let table = Table::parse(aligned.as_bytes()).expect("valid");
    assert_eq!(table.weights_f32(&dart).expect("present")[0], 0.5);
    assert_eq!(table.weights_f32(&smooth).expect("present")[0], 0.25);
    assert_eq!(
        table.coverage(),
        "interior valences 3, darts of valences 3, no boundary vertices, n = 1"
    );
    // The second entry is the dart's: byte 3 is 1, the sector 2.
    let second = HEADER_SIZE + ENTRY_SIZE;
    assert_eq!(bytes[second + 3], 1);
    assert_eq!(bytes[second + 8], 2);
    assert_eq!(bytes[HEADER_SIZE + 3], 0);
    assert!(
        dart.to_string().contains("dart of valence 3, sector 2"),
        "{dart}"
    );

    let mut b = bytes.clone();
    b[second + 3] = 2;
    reseal(&mut b);
    assert_eq!(
        parse(&b),
        Err(TableError::BadField {
            field: "section feature",
            value: 2
        })
    );
    let mut b = bytes.clone();
    b[second + 2] = 1; // boundary, and a dart
    reseal(&mut b);
    assert_eq!(
        parse(&b),
        Err(TableError::BadField {
            field: "section feature",
            value: 1
        })
    );
    let boundary_dart = SectionKey {
        boundary: true,
        ..dart
    };
    assert!(matches!(
        encode(meta, &[(boundary_dart, 14, vec![0.5; 14])]),
        Err(TableError::Encode(_))
    ));
}

#[test]
fn section_outside_the_file() {
    let mut b = sample();
    let at = HEADER_SIZE + 24; // first entry's offset
    let len = b.len() as u64;
    b[at..at + 8].copy_from_slice(&len.to_le_bytes());
    reseal(&mut b);
    assert!(matches!(
        parse(&b),
        Err(TableError::SectionOutOfBounds { index: 0, .. })
    ));
}

#[test]
fn misaligned_and_wrong_shape() {
    let mut b = sample();
    let at = HEADER_SIZE + 24;
    let offset = u64_at(&b, at);
    b[at..at + 8].copy_from_slice(&(offset + 2).to_le_bytes());
    reseal(&mut b);
    assert!(matches!(
        parse(&b),
        Err(TableError::Misaligned { index: 0, .. })
    ));
    let mut b = sample();
    let width_at = HEADER_SIZE + 20;
    b[width_at..width_at + 4].copy_from_slice(&15u32.to_le_bytes());
    reseal(&mut b);
    assert!(matches!(
        parse(&b),
        Err(TableError::WrongShape { index: 0, .. })
    ));
    // A section pointing into the header or index.
    let mut b = sample();
    b[at..at + 8].copy_from_slice(&8u64.to_le_bytes());
    reseal(&mut b);
    assert!(matches!(
        parse(&b),
        Err(TableError::Misaligned { index: 0, .. })
    ));
}

#[test]
fn missing_valence_or_rate_names_the_coverage() {
    let bytes = sample();
    let aligned = AlignedBytes::from_slice(&bytes);
    let table = Table::parse(aligned.as_bytes()).expect("valid");
    let e = table
        .weights_f32(&key(StencilKind::Position, PointSet::Dual, 9, 2))
        .expect_err("no valence 9");
    assert!(matches!(e, TableError::MissingSection { .. }));
    assert!(
        e.to_string().contains("valence 9") && e.to_string().contains("interior valences 3"),
        "{e}"
    );
    let e = table
        .weights_f32(&key(StencilKind::Position, PointSet::Dual, 3, 24))
        .expect_err("no n = 24");
    assert!(e.to_string().contains("n = 1..=3"), "{e}");
    let e = table
        .weights_f64(&key(StencilKind::Position, PointSet::Dual, 3, 2))
        .expect_err("f32 table");
    assert!(matches!(e, TableError::PrecisionMismatch { .. }));
}

#[test]
fn unaligned_buffer_is_an_error() {
    let bytes = sample();
    let aligned = AlignedBytes::from_slice(&[&[0u8][..], &bytes].concat());
    assert_eq!(
        Table::parse(&aligned.as_bytes()[1..]).err(),
        Some(TableError::UnalignedBuffer)
    );
}

#[test]
fn duplicate_sections_are_refused_by_the_writer() {
    let meta = TableMeta {
        scheme: SchemeId::CatmullClark,
        precision: Precision::F32,
        corners: false,
    };
    let k = key(StencilKind::Position, PointSet::Dual, 3, 1);
    let e = encode(meta, &[(k, 1, vec![1.0]), (k, 1, vec![1.0])]).expect_err("duplicate");
    assert!(matches!(e, TableError::DuplicateSection { .. }));
    let e = encode(meta, &[(k, 2, vec![1.0])]).expect_err("wrong length");
    assert!(matches!(e, TableError::Encode(_)));
}

#[test]
fn triangle_point_sets_count_and_belong_to_triangle_schemes() {
    for n in 1..=24u64 {
        // (n+1)(n+2)/2 grid points i + j <= n; n^2 small triangles.
        let grid = (0..=n).map(|j| n - j + 1).sum::<u64>();
        let small = (0..n).map(|j| 2 * (n - j) - 1).sum::<u64>();
        assert_eq!(PointSet::TrianglePrimal.count(n as u32), grid);
        assert_eq!(PointSet::TriangleDual.count(n as u32), small);
    }
    let loop_ = TableMeta {
        scheme: SchemeId::Loop,
        precision: Precision::F32,
        corners: false,
    };
    let tri = key(StencilKind::Position, PointSet::TrianglePrimal, 6, 1);
    let bytes = encode(loop_, &[(tri, 12, vec![0.5; 36])]).expect("valid");
    parse(&bytes).expect("a Loop table with triangle sections");
    let quad = key(StencilKind::Position, PointSet::Primal, 6, 1);
    let e = encode(loop_, &[(quad, 1, vec![1.0; 4])]).expect_err("quad grid in a Loop table");
    assert!(matches!(e, TableError::WrongPointSet { .. }));
    // The reader refuses it too: relabel the valid file's scheme as Catmull–Clark.
    let mut b = bytes.clone();
    b[52..56].copy_from_slice(&(SchemeId::CatmullClark as u32).to_le_bytes());
    reseal(&mut b);
    assert!(matches!(parse(&b), Err(TableError::WrongPointSet { .. })));
}

/// The compact Loop pieces: the shared ones (vertex masks, `A`) belong to both families, the
/// Loop basis, the sub-triangle matrices and the rate markers to triangle schemes only; the
/// rate markers are what the coverage line reads the rates from.
#[test]
fn compact_loop_point_sets_belong_to_triangle_schemes() {
    let loop_ = TableMeta {
        scheme: SchemeId::Loop,
        precision: Precision::F64,
        corners: false,
    };
    let cc = TableMeta {
        scheme: SchemeId::CatmullClark,
        ..loop_
    };
    let basis = key(StencilKind::Position, PointSet::LoopBasis, 0, 4);
    let subs = key(StencilKind::Position, PointSet::SubTriangles, 6, 0);
    let a = key(StencilKind::Position, PointSet::Subdivision, 6, 0);
    let mask = key(StencilKind::Position, PointSet::VertexMask, 6, 0);
    let rate = |n| key(StencilKind::Position, PointSet::TriangleRate, 0, n);
    assert_eq!(PointSet::LoopBasis.rows(4, 17), 17);
    assert_eq!(PointSet::SubTriangles.rows(0, 12), 36);
    assert_eq!(PointSet::TriangleRate.rows(7, 0), 0);
    let sections = vec![
        (basis, 3, vec![0.0; 9]),
        (subs, 12, vec![0.0; 36 * 12]),
        (a, 12, vec![0.0; 144]),
        (mask, 12, vec![0.0; 12]),
        (rate(1), 0, vec![]),
        (rate(2), 0, vec![]),
        (rate(5), 0, vec![]),
    ];
    let bytes = encode(loop_, &sections).expect("valid");
    let aligned = AlignedBytes::from_slice(&bytes);
    let table = Table::parse(aligned.as_bytes()).expect("valid");
    assert_eq!(
        table.coverage(),
        "interior valences 6, no boundary vertices, n = 1..=2, 5"
    );
    assert!(table.weights_f64(&rate(2)).expect("present").is_empty());
    for loop_only in [
        PointSet::LoopBasis,
        PointSet::SubTriangles,
        PointSet::TriangleRate,
    ] {
        let k = key(StencilKind::Position, loop_only, 0, 0);
        let e = encode(cc, &[(k, 0, vec![])]).expect_err("a Loop piece in a quad table");
        assert!(
            matches!(e, TableError::WrongPointSet { .. }),
            "{loop_only:?}"
        );
    }
    encode(cc, &[(a, 12, vec![0.0; 144]), (mask, 12, vec![0.0; 12])])
        .expect("the shared pieces belong to quad tables too");
}

#[test]
fn sqrt3_is_scheme_five_and_a_triangle_scheme() {
    // docs/table-format.md: scheme id 5 = sqrt3, triangle point sets only.
    assert_eq!(SchemeId::Sqrt3 as u32, 5);
    assert_eq!(SchemeId::from_name("sqrt3"), Some(SchemeId::Sqrt3));
    assert!(SchemeId::Sqrt3.is_triangle());
    let meta = TableMeta {
        scheme: SchemeId::Sqrt3,
        precision: Precision::F32,
        corners: false,
    };
    let tri = key(StencilKind::Position, PointSet::TrianglePrimal, 5, 1);
    let bytes = encode(meta, &[(tri, 24, vec![0.25; 72])]).expect("valid");
    assert_eq!(&bytes[52..56], &5u32.to_le_bytes());
    parse(&bytes).expect("a sqrt3 table with triangle sections");
    let quad = key(StencilKind::Position, PointSet::Primal, 5, 1);
    let e = encode(meta, &[(quad, 1, vec![1.0; 4])]).expect_err("quad grid in a sqrt3 table");
    assert!(matches!(e, TableError::WrongPointSet { .. }));
}

proptest! {
    /// Mutating random bytes of a valid table (re-sealed or not) gives Ok or a clean Err.
    #[test]
    fn random_mutations_never_panic(
        edits in proptest::collection::vec((0usize..4096, any::<u8>()), 1..8),
        reseal_it in any::<bool>(),
        cut in proptest::option::of(0usize..4096),
    ) {
        let mut b = sample();
        for (at, value) in edits {
            let at = at % b.len();
            b[at] = value;
        }
        if reseal_it && b.len() > HEADER_SIZE {
            reseal(&mut b);
        }
        if let Some(cut) = cut {
            b.truncate(cut % (b.len() + 1));
        }
        let _ = parse(&b);
    }
}

/// A NaN or an infinite weight written into a table passes the checksum (it was written so)
/// but not `check_finite`, which names the section and the point.
#[test]
fn non_finite_weights_are_found_behind_a_valid_checksum() {
    let meta = TableMeta {
        scheme: SchemeId::CatmullClark,
        precision: Precision::F32,
        corners: false,
    };
    let k = key(StencilKind::Position, PointSet::Dual, 3, 2);
    for bad in [f64::NAN, f64::INFINITY, -1e300] {
        let mut weights = vec![0.25; 4 * 14];
        weights[2 * 14 + 5] = bad;
        let bytes = encode(meta, &[(k, 14, weights)]).expect("written");
        let aligned = AlignedBytes::from_slice(&bytes);
        let index = TableIndex::parse(aligned.as_bytes()).expect("the checksum holds");
        match index.check_finite(aligned.as_bytes()) {
            Err(TableError::NonFinite { key, point }) => {
                assert_eq!((key, point), (k, 2), "{bad}");
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
    let sample = AlignedBytes::from_slice(&sample());
    let index = TableIndex::parse(sample.as_bytes()).expect("valid");
    index.check_finite(sample.as_bytes()).expect("all finite");
}

/// The compact region pieces (format version 5): a region basis is one row of any width, the
/// tile rows of a region have as many rows as the key's `n` says; both belong to triangle
/// schemes only, and a region basis names no patch (the coverage line lists the region rows'
/// valence, not a valence 0).
#[test]
fn compact_region_point_sets_have_their_shapes() {
    let butterfly = TableMeta {
        scheme: SchemeId::Butterfly,
        precision: Precision::F64,
        corners: false,
    };
    assert_eq!(PointSet::RegionBasis.rows(24, 10_476), 1);
    assert_eq!(PointSet::RegionRows.rows(31, 27), 31);
    let basis = key(StencilKind::DerivativeU, PointSet::RegionBasis, 0, 3);
    let rows = SectionKey {
        sector: 4,
        ..key(StencilKind::Position, PointSet::RegionRows, 5, 7)
    };
    let rate = key(StencilKind::Position, PointSet::TriangleRate, 0, 3);
    let bytes = encode(
        butterfly,
        &[
            (basis, 5, vec![0.5; 5]),
            (rows, 3, vec![0.25; 21]),
            (rate, 0, vec![]),
        ],
    )
    .expect("valid");
    let aligned = AlignedBytes::from_slice(&bytes);
    let table = Table::parse(aligned.as_bytes()).expect("valid");
    assert_eq!(table.weights_f64(&rows).expect("present").len(), 21);
    assert_eq!(
        table.coverage(),
        "interior valences 5, no boundary vertices, n = 3"
    );
    // A wrong row count is a wrong shape.
    let e = encode(butterfly, &[(rows, 3, vec![0.25; 18])]).expect_err("6 rows, not 7");
    assert!(matches!(e, TableError::Encode(_)), "{e}");
    let cc = TableMeta {
        scheme: SchemeId::CatmullClark,
        ..butterfly
    };
    for piece in [basis, rows] {
        let e =
            encode(cc, &[(piece, 1, vec![0.0; 7])]).expect_err("a region piece in a quad table");
        assert!(matches!(e, TableError::WrongPointSet { .. }), "{piece}");
    }
}
