//! Generating every curve scheme's stencils for n = 1..24, exact and f64.
//!
//! `cargo bench -p stencilgen --bench curve_stencils`

#![allow(missing_docs)] // criterion_group! generates an undocumented function

use criterion::{criterion_group, criterion_main, Criterion};
use num_rational::BigRational;
use schemes::curve::CURVE_SCHEME_NAMES;
use schemes::CurveScheme;
use stencilgen::curve_stencils;

fn all_rates<S: stencilgen::Scalar>(scheme: &CurveScheme, derivative: bool) -> usize {
    (1..=24u32)
        .map(|n| match curve_stencils::<S>(scheme, n, derivative) {
            Ok(s) => s.functions.len(),
            Err(e) => panic!("{} n = {n}: {e}", scheme.name),
        })
        .sum()
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("curve n=1..24");
    group.sample_size(10);
    for name in CURVE_SCHEME_NAMES {
        let Some(scheme) = CurveScheme::by_name(name) else {
            continue;
        };
        let derivative = scheme.reproduces_linear();
        group.bench_function(format!("{name}/exact"), |b| {
            b.iter(|| {
                all_rates::<BigRational>(&scheme, false)
                    + if derivative {
                        all_rates::<BigRational>(&scheme, true)
                    } else {
                        0
                    }
            })
        });
        group.bench_function(format!("{name}/f64"), |b| {
            b.iter(|| {
                all_rates::<f64>(&scheme, false)
                    + if derivative {
                        all_rates::<f64>(&scheme, true)
                    } else {
                        0
                    }
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
