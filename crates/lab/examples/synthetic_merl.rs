//! Writes a MERL binary file tabulating a material, optionally with multiplicative noise:
//! synthetic measured data for trying `facette fit`.
//!
//! cargo run --release -p facette-lab --example synthetic_merl -- \
//!     '{type = "il", kd = 0.425, ni = 1.2, alpha = 0.143, evaluation = "quadrature", samples = 256}' \
//!     white-paint-like.binary [NOISE] [SEED]

use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::recipe::{build_material, parse_inline_table};
use facette_bsdf::BsdfContext;
use facette_lab::merl::MerlBrdf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        return Err("usage: synthetic_merl MATERIAL_TOML OUTPUT [NOISE] [SEED]".into());
    }
    let bsdf = build_material(&parse_inline_table(&args[0])?)?;
    if bsdf.is_stochastic() {
        return Err("use a deterministic evaluation (e.g. evaluation = \"quadrature\")".into());
    }
    let noise: f64 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(0.0);
    let seed: u64 = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(1);
    let start = std::time::Instant::now();
    let mut m = MerlBrdf::from_fn(|_, i, o| {
        Some(bsdf.eval(o, i, &BsdfContext::RADIANCE, &mut Pcg32::new(1, 1)))
    });
    if noise > 0.0 {
        m = m.with_multiplicative_noise(noise, seed);
    }
    m.save(std::path::Path::new(&args[1]))?;
    eprintln!(
        "wrote {} ({} valid bins) in {:.1} s",
        args[1],
        m.valid_bins(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
