//! Cost and accuracy of the albedo tables' entry rules (diagnostic; the figures of
//! `models/multiple_scattering/albedo_tables.rs` and docs/materials.md).
//!
//! `cargo run --profile optimized-tests -p facette-bsdf --example albedo_table_cost -- [TOL...]`
//! builds tables (GGX and Beckmann, smith-correlated: conductor, dielectric η = 1.5 and
//! 1/1.5 sides; GGX v-cavity conductor) with the fixed 16-point rule and adaptively at each
//! TOL (default 1e-4 1e-5), and measures every entry of the rough rows against a
//! tolerance-1e-10 reference (cached under /tmp). `WORST=1` lists the worst entries.
use facette_bsdf::microfacet::{Beckmann, Ggx, Masking, Ndf};
use facette_bsdf::models::multiple_scattering::albedo_tables::{
    AlbedoTable, EntryQuadrature, TableFresnel, ALPHA_NODES, MU_NODES,
};

fn reference(ndf: &Ndf, masking: Masking, fresnel: TableFresnel, name: &str) -> Vec<f64> {
    let path = format!("/tmp/facette-albedo-reference-1e-10-{name}.txt");
    if let Ok(s) = std::fs::read_to_string(&path) {
        let v: Vec<f64> = s
            .split_whitespace()
            .filter_map(|x| x.parse().ok())
            .collect();
        if v.len() == ALPHA_NODES * MU_NODES {
            return v;
        }
    }
    let t = AlbedoTable::build_with(
        ndf,
        masking,
        fresnel,
        EntryQuadrature::Adaptive { tolerance: 1e-10 },
    );
    eprintln!("reference {name}: {:.1} s", t.build_seconds());
    let v: Vec<f64> = (0..ALPHA_NODES)
        .flat_map(|j| (0..MU_NODES).map(move |k| (j, k)))
        .map(|(j, k)| t.entry(j, k))
        .collect();
    let text: Vec<String> = v.iter().map(|x| format!("{x:e}")).collect();
    let _ = std::fs::write(&path, text.join("\n"));
    v
}

fn main() {
    let tols: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let tols = if tols.is_empty() {
        vec![1e-4, 1e-5]
    } else {
        tols
    };
    let ggx = Ndf::Ggx(Ggx::isotropic(0.3).unwrap());
    let beckmann = Ndf::Beckmann(Beckmann::isotropic(0.3).unwrap());
    let smith = Masking::SmithCorrelated;
    for (name, ndf, masking, fresnel) in [
        ("ggx-conductor", &ggx, smith, TableFresnel::One),
        (
            "ggx-dielectric-1.5",
            &ggx,
            smith,
            TableFresnel::Dielectric(1.5),
        ),
        (
            "ggx-dielectric-1/1.5",
            &ggx,
            smith,
            TableFresnel::Dielectric(1.0 / 1.5),
        ),
        ("beckmann-conductor", &beckmann, smith, TableFresnel::One),
        (
            "beckmann-dielectric-1.5",
            &beckmann,
            smith,
            TableFresnel::Dielectric(1.5),
        ),
        (
            "beckmann-dielectric-1/1.5",
            &beckmann,
            smith,
            TableFresnel::Dielectric(1.0 / 1.5),
        ),
        (
            "ggx-v-cavity-conductor",
            &ggx,
            Masking::VCavity,
            TableFresnel::One,
        ),
    ] {
        if std::env::var("ONLY").is_ok_and(|o| !name.contains(&o)) {
            continue;
        }
        let r = reference(ndf, masking, fresnel, &name.replace('/', "over"));
        let mut rules = vec![EntryQuadrature::Fixed { points: 16 }];
        rules.extend(
            tols.iter()
                .map(|&tolerance| EntryQuadrature::Adaptive { tolerance }),
        );
        for rule in rules {
            let t = AlbedoTable::build_with(ndf, masking, fresnel, rule);
            let (mut abs, mut rel, mut over) = (0.0f64, 0.0f64, 0usize);
            let mut worst: Vec<(f64, usize, usize)> = Vec::new();
            for j in 1..ALPHA_NODES {
                for k in 0..MU_NODES {
                    let (e, x) = (t.entry(j, k), r[j * MU_NODES + k]);
                    abs = abs.max((e - x).abs());
                    worst.push(((e - x).abs(), j, k));
                    let rk = (e - x).abs() / x.max(1e-300);
                    if rk > rel && std::env::var_os("WORST").is_some() {
                        println!("   rel {rk:.1e} at j {j} k {k}: E {e:.9} ref {x:.9}");
                    }
                    rel = rel.max(rk);
                    if let Some(b) = t.entry_error(j, k) {
                        if (e - x).abs() > b + 1e-9 * x {
                            over += 1;
                            if std::env::var_os("WORST").is_some() {
                                println!("   above estimate: j {j} k {k}: E {e:.9} ref {x:.9} est {b:.1e}");
                            }
                        }
                    }
                }
            }
            if std::env::var_os("WORST").is_some() {
                worst.sort_by(|a, b| b.0.total_cmp(&a.0));
                for &(d, j, k) in worst.iter().take(12) {
                    println!(
                        "   j {j} k {k} α {:.4} μ {:.4}: E {:.6} ref {:.6} |Δ| {d:.1e} est {:?}",
                        facette_bsdf::models::multiple_scattering::albedo_tables::row_alpha(j),
                        (k as f64 / (MU_NODES - 1) as f64).powi(2),
                        t.entry(j, k),
                        r[j * MU_NODES + k],
                        t.entry_error(j, k)
                    );
                }
            }
            println!(
                "{name:26} {rule:?}: {:.3} s, {} evaluations, max abs {abs:.1e} rel {rel:.1e}, estimate {:?}, entries above their estimate {over}",
                t.build_seconds(),
                t.evaluations(),
                t.max_error(),
            );
        }
    }
}
