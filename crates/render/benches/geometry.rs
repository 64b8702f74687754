//! Geometry benchmarks on the generated torus-knot mesh at 10k, 100k and 1M triangles:
//!
//! - `bvh_build/<size>`: building the scene (triangle boxes + SAH BVH), on the global
//!   rayon pool (all cores) and on a one-thread pool;
//! - `closest_hit/<size>/<rays>/<threads>`: `SceneGeometry::intersect` over a batch of
//!   rays, on pools of one and two threads; throughput in rays/s ("elements/s");
//!   `coherent` rays come from a pinhole camera framing the mesh (256×256), `incoherent`
//!   ones start at random points of the bounding box in random directions (as diffuse
//!   bounces do);
//! - `occluded/<size>/incoherent/<threads>`: the any-hit query on the incoherent rays;
//! - `ply_load/<format>`: `read_ply` of a 1M-triangle grid (708 × 708 vertices with
//!   normals and uvs) in binary little-endian (29 MB) and ASCII, from the page cache;
//!   throughput in bytes/s.
//!
//! Short measurement times keep the whole run to a few minutes:
//! `cargo bench -p facette-render --bench geometry`. Results are recorded in the
//! geometry report / docs/performance.md, never asserted.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use facette_bsdf::math::rng::{Pcg32, RandomSource};
use facette_bsdf::math::warp::square_to_uniform_sphere;
use facette_render::geometry::generate::TorusKnot;
use facette_render::geometry::mesh_io::read_ply;
use facette_render::geometry::{Ray, SceneGeometry, Shape, Transform, Vec3};
use rayon::prelude::*;
use std::sync::Arc;
use std::time::Duration;

const SIZES: [(&str, usize); 3] = [("10k", 10_000), ("100k", 100_000), ("1M", 1_000_000)];

fn mesh_shapes(triangles: usize) -> Vec<Shape> {
    let mesh = TorusKnot::with_triangles(triangles)
        .mesh(&Transform::IDENTITY)
        .expect("generated mesh is valid");
    vec![Shape::Mesh(Arc::new(mesh))]
}

fn coherent_rays() -> Vec<Ray> {
    let cam = Transform::look_at(Vec3::new(0.0, -4.0, 1.5), Vec3::ZERO, Vec3::Z).unwrap();
    let n = 256;
    let half_fov = 0.4f64;
    let mut rays = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let x = (2.0 * (i as f64 + 0.5) / n as f64 - 1.0) * half_fov.tan();
            let y = (1.0 - 2.0 * (j as f64 + 0.5) / n as f64) * half_fov.tan();
            rays.push(Ray::infinite(
                cam.point(Vec3::ZERO),
                cam.vector(Vec3::new(x, y, 1.0)),
            ));
        }
    }
    rays
}

fn incoherent_rays(scene: &SceneGeometry, count: usize) -> Vec<Ray> {
    let b = scene.bounds();
    let mut rng = Pcg32::new(2024, 0);
    (0..count)
        .map(|_| {
            let u = Vec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
            let o = b.min + u * (b.max - b.min);
            Ray::infinite(o, square_to_uniform_sphere(rng.next_2d()))
        })
        .collect()
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

fn trace(scene: &SceneGeometry, rays: &[Ray]) -> f64 {
    rays.par_chunks(256)
        .map(|chunk| {
            chunk
                .iter()
                .filter_map(|r| scene.intersect(r))
                .map(|h| h.t)
                .sum::<f64>()
        })
        .sum()
}

fn occluded(scene: &SceneGeometry, rays: &[Ray]) -> usize {
    rays.par_chunks(256)
        .map(|chunk| chunk.iter().filter(|r| scene.occluded_ray(r)).count())
        .sum()
}

fn bench_build(c: &mut Criterion) {
    let mut g = c.benchmark_group("bvh_build");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(4));
    let one = pool(1);
    for (name, n) in SIZES {
        let shapes = mesh_shapes(n);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function(BenchmarkId::new(name, "all_threads"), |b| {
            b.iter(|| SceneGeometry::new(black_box(shapes.clone())).unwrap())
        });
        g.bench_function(BenchmarkId::new(name, "1_thread"), |b| {
            b.iter(|| one.install(|| SceneGeometry::new(black_box(shapes.clone())).unwrap()))
        });
    }
    g.finish();
}

fn bench_trace(c: &mut Criterion) {
    let pools = [(1usize, pool(1)), (2, pool(2))];
    let coherent = coherent_rays();
    let scenes: Vec<(&str, SceneGeometry, Vec<Ray>)> = SIZES
        .iter()
        .map(|&(name, n)| {
            let scene = SceneGeometry::new(mesh_shapes(n)).unwrap();
            let incoherent = incoherent_rays(&scene, 65_536);
            (name, scene, incoherent)
        })
        .collect();

    let mut g = c.benchmark_group("closest_hit");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    for (name, scene, incoherent) in &scenes {
        for (kind, rays) in [("coherent", &coherent), ("incoherent", incoherent)] {
            g.throughput(Throughput::Elements(rays.len() as u64));
            for (threads, p) in &pools {
                g.bench_function(
                    BenchmarkId::new(format!("{name}/{kind}"), format!("{threads}_threads")),
                    |b| b.iter(|| p.install(|| trace(scene, black_box(rays)))),
                );
            }
        }
    }
    g.finish();

    let mut g = c.benchmark_group("occluded");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    for (name, scene, incoherent) in &scenes {
        g.throughput(Throughput::Elements(incoherent.len() as u64));
        for (threads, p) in &pools {
            g.bench_function(
                BenchmarkId::new(format!("{name}/incoherent"), format!("{threads}_threads")),
                |b| b.iter(|| p.install(|| occluded(scene, black_box(incoherent)))),
            );
        }
    }
    g.finish();
}

/// A 1M-triangle grid as PLY text or binary little-endian: `n × n` vertices (position,
/// normal, uv as f32), two triangles per cell (uchar count, int indices).
fn grid_ply(n: usize, binary: bool) -> Vec<u8> {
    let format = if binary {
        "binary_little_endian"
    } else {
        "ascii"
    };
    let mut out = format!(
        "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        n * n,
        2 * (n - 1) * (n - 1)
    )
    .into_bytes();
    for j in 0..n {
        for i in 0..n {
            let (u, v) = (i as f32 / (n - 1) as f32, j as f32 / (n - 1) as f32);
            let values = [u, v, (u * 7.0).sin() * 0.1, 0.0, 0.0, 1.0, u, v];
            if binary {
                values.iter().for_each(|x| out.extend(x.to_le_bytes()));
            } else {
                let line: Vec<String> = values.iter().map(f32::to_string).collect();
                out.extend(line.join(" ").bytes());
                out.push(b'\n');
            }
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = (j * n + i) as i32;
            let n = n as i32;
            for t in [[a, a + 1, a + n], [a + 1, a + n + 1, a + n]] {
                if binary {
                    out.push(3);
                    t.iter().for_each(|x| out.extend(x.to_le_bytes()));
                } else {
                    out.extend(format!("3 {} {} {}\n", t[0], t[1], t[2]).bytes());
                }
            }
        }
    }
    out
}

fn bench_ply_load(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let mut g = c.benchmark_group("ply_load");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    for (name, binary) in [("binary_le", true), ("ascii", false)] {
        let bytes = grid_ply(708, binary);
        let path = dir.path().join(format!("grid-{name}.ply"));
        std::fs::write(&path, &bytes).expect("written");
        g.throughput(Throughput::Bytes(bytes.len() as u64));
        g.bench_function(name, |b| {
            b.iter(|| read_ply(black_box(&path)).expect("valid PLY"))
        });
    }
    g.finish();
}

criterion_group!(benches, bench_build, bench_trace, bench_ply_load);
criterion_main!(benches);
