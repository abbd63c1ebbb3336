//! The embedded tables are exactly what the generator makes today.
//!
//! Every embedded table is compact (Catmull–Clark, its pinned-corner companion, Loop: a tenth of
//! a second each; butterfly and √3: the regular basis at 24 rates by the cascade iteration,
//! seconds each in the dev profile) and is regenerated whole and compared byte for byte. Each
//! test runs when its table's cargo feature is enabled (all of them by default).

#[cfg(feature = "catmull-clark")]
#[test]
fn regenerated_default_table_is_byte_identical() {
    let fresh = stencilgen::table::default_table().expect("the default table generates");
    let embedded = tables::default_catmull_clark();
    assert_eq!(fresh.len(), embedded.len(), "sizes differ");
    assert!(
        fresh == embedded,
        "the embedded default table differs from a fresh generation"
    );
    let table = table_format::Table::parse(embedded).expect("the embedded table is valid");
    // The darts of valences 3..=8, every sector: 3 + 4 + .. + 8 = 33 patches.
    let darts = table
        .entries
        .iter()
        .filter(|e| {
            e.key.feature == table_format::Feature::Dart
                && e.key.points == table_format::PointSet::Subdivision
        })
        .count();
    assert_eq!(darts, 33);
    println!(
        "default table: {} bytes, {} sections; {}",
        table.size(),
        table.entries.len(),
        table.coverage()
    );
}

#[cfg(feature = "catmull-clark")]
#[test]
fn regenerated_corner_table_is_byte_identical() {
    let fresh = stencilgen::table::default_corner_table().expect("the corner table generates");
    let embedded = tables::default_catmull_clark_corners();
    assert!(
        fresh == embedded,
        "the embedded corner table differs from a fresh generation"
    );
    let table = table_format::Table::parse(embedded).expect("the embedded table is valid");
    assert!(table.meta.corners);
    println!(
        "corner table: {} bytes, {} sections; {}",
        table.size(),
        table.entries.len(),
        table.coverage()
    );
}

#[cfg(feature = "loop")]
#[test]
fn regenerated_loop_table_is_byte_identical() {
    let fresh = stencilgen::triangle_table::default_loop_table().expect("the Loop table generates");
    let embedded = tables::default_loop();
    assert!(
        fresh == embedded,
        "the embedded Loop table differs from a fresh generation"
    );
    let table = table_format::Table::parse(embedded).expect("the embedded table is valid");
    assert_eq!(table.meta.scheme, table_format::SchemeId::Loop);
    assert_eq!(table.meta.precision, table_format::Precision::F64);
    assert!(table.entries.iter().all(|e| !e.key.points.is_grid()));
    println!(
        "Loop table: {} bytes, {} sections; {}",
        table.size(),
        table.entries.len(),
        table.coverage()
    );
}

#[cfg(feature = "butterfly")]
#[test]
fn regenerated_butterfly_table_is_byte_identical() {
    let fresh = stencilgen::butterfly_table::default_butterfly_table()
        .expect("the butterfly table generates");
    let embedded = tables::default_butterfly();
    assert!(
        fresh == embedded,
        "the embedded butterfly table differs from a fresh generation"
    );
    let table = table_format::Table::parse(embedded).expect("the embedded table is valid");
    assert_eq!(table.meta.scheme, table_format::SchemeId::Butterfly);
    println!(
        "butterfly table: {} bytes, {} sections; {}",
        table.size(),
        table.entries.len(),
        table.coverage()
    );
}

#[cfg(feature = "sqrt3")]
#[test]
fn regenerated_sqrt3_table_is_byte_identical() {
    let fresh = stencilgen::sqrt3_table::default_sqrt3_table().expect("the sqrt3 table generates");
    let embedded = tables::default_sqrt3();
    assert!(
        fresh == embedded,
        "the embedded sqrt3 table differs from a fresh generation"
    );
    let table = table_format::Table::parse(embedded).expect("the embedded table is valid");
    assert_eq!(table.meta.scheme, table_format::SchemeId::Sqrt3);
    println!(
        "sqrt3 table: {} bytes, {} sections; {}",
        table.size(),
        table.entries.len(),
        table.coverage()
    );
}
