//! Times the default stencil set once, exact and f64 (a quick check; the criterion bench
//! `quad_stencils` gives the medians quoted in docs/benchmarks.md).
use num_rational::BigRational;
use schemes::QuadScheme;
use stencilgen::stencil_set::{stencil_set, StencilSetSpec};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cc = QuadScheme::by_name("catmull-clark").ok_or("catmull-clark")?;
    let spec = StencilSetSpec::default_catmull_clark();
    let t = std::time::Instant::now();
    let f = stencil_set::<f64>(&cc, &spec)?;
    println!("f64: {} stencil grids in {:.2?}", f.len(), t.elapsed());
    let t = std::time::Instant::now();
    let e = stencil_set::<BigRational>(&cc, &spec)?;
    println!("exact: {} stencil grids in {:.2?}", e.len(), t.elapsed());
    Ok(())
}
