//! Energy of interfaced-Lambertian V-cavity walks by scattering order (diagnostic).
use facette_bsdf::math::rng::{Pcg32, RandomSource};
use facette_bsdf::math::spherical_direction;
use facette_bsdf::microfacet::{Beckmann, Distribution};
use facette_bsdf::models::il::vcavity::{walk, IlFacet};
use facette_bsdf::Spectrum;
fn main() {
    let ni = 1.5;
    let re = facette_bsdf::fresnel::external_diffuse_reflectance(ni);
    let ri = facette_bsdf::fresnel::internal_diffuse_reflectance(ni);
    let kd = 1.0;
    let facet = IlFacet {
        ni,
        kd: Spectrum::splat(kd),
        body_factor: Spectrum::splat(kd / (ni * ni * (1.0 - kd * ri))),
    };
    let _ = re;
    for alpha in [0.1, 0.5, 1.0] {
        let d = Beckmann::isotropic(alpha).unwrap();
        for deg in [0.0f64, 30.0, 60.0, 85.0] {
            let i = spherical_direction(deg.to_radians(), 0.0);
            let mut rng = Pcg32::new(1, 2);
            let n = 1_000_000;
            let (mut single, mut multi_body, mut multi_spec) = (0.0, 0.0, 0.0);
            for _ in 0..n {
                let m = d.sample_normal(rng.next_2d());
                if let Some(w) = walk(&facet, m, i, &mut rng) {
                    let e = w.weight[0];
                    if w.vertices == 1 {
                        single += e
                    } else if w.had_body_event {
                        multi_body += e
                    } else {
                        multi_spec += e
                    }
                }
            }
            let nf = n as f64;
            println!("alpha {alpha} θ {deg}: single {:.4} multi(body) {:.4} multi(pure specular) {:.4} total {:.4}", single / nf, multi_body / nf, multi_spec / nf, (single + multi_body + multi_spec) / nf);
        }
    }
}
