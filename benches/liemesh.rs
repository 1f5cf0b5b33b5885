//! Criterion benchmarks of issue 6: (a) the six presets end to end, (b) sphere and
//! ellipsoid at about 10^4, 10^5 and 10^6 triangles: sampling, the chart triangulation with
//! its closing and first flip pass, and the whole pipeline (the difference is the
//! relaxation, its flip pass and the assembly of the working-precision vertices),
//! (c) fig6 sampling per scalar type, (d) spade's bulk load of the same chart points, and
//! (e) the fidelity workload: the coarsest sphere and ellipsoid meshes within 0.7° of the
//! field normals, refinement included, as `liemesh bench`'s scan finds them, and
//! (f) `Mesh::validate` on the 10^5-triangle sphere and ellipsoid beside the meshing of the
//! same mesh (validation should cost at most a quarter of it).

use criterion::{
    criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode, Throughput,
};
// The workloads of `liemesh bench` (β band and Δt shrunk by √(target / base), the fidelity
// scan), from the one file that defines them for both.
#[allow(dead_code)]
#[path = "../src/cli/workloads.rs"]
mod workloads;

use liemesh::model::LieField;
use liemesh::preset::Preset;
use liemesh::scalar::Dual;
use spade::Triangulation as _;
use std::hint::black_box;
use std::time::Duration;
use workloads::workload_params as workload;

fn configure<'a>(
    c: &'a mut Criterion,
    name: &str,
) -> criterion::BenchmarkGroup<'a, criterion::measurement::WallTime> {
    let mut g = c.benchmark_group(name);
    g.sample_size(10)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(500));
    g
}

fn presets(c: &mut Criterion) {
    let mut g = configure(c, "presets");
    for preset in Preset::ALL {
        let field = LieField::<f64>::new(&preset.invariant());
        let params = preset.params();
        let triangles = liemesh::run(&field, &params).unwrap().mesh.triangles.len();
        g.throughput(Throughput::Elements(triangles as u64));
        g.bench_function(preset.name(), |b| {
            b.iter(|| liemesh::run(black_box(&field), &params).unwrap())
        });
    }
    g.finish();
}

fn sizes(c: &mut Criterion) {
    let mut g = configure(c, "surfaces");
    for (ellipsoid, label) in [(false, "sphere"), (true, "ellipsoid")] {
        for (target, tag, seconds) in [
            (10_000, "1e4", 2),
            (100_000, "1e5", 5),
            (1_000_000, "1e6", 25),
        ] {
            // Ten samples of the slowest function (end to end) fit the measurement time;
            // at a second per run, one run per sample.
            g.measurement_time(Duration::from_secs(seconds))
                .sampling_mode(if target > 10_000 {
                    SamplingMode::Flat
                } else {
                    SamplingMode::Auto
                });
            let (inv, params) = workload(ellipsoid, target);
            let field = LieField::<f64>::new(&inv);
            let samples = liemesh::sample::sample(&field, &params).unwrap();
            let (mesh, _) = liemesh::triangulate::triangulate(&samples, true, true).unwrap();
            g.throughput(Throughput::Elements(mesh.triangles.len() as u64));
            let id = format!("{label}-{tag}");
            g.bench_function(BenchmarkId::new("sample", &id), |b| {
                b.iter(|| liemesh::sample::sample(black_box(&field), &params).unwrap())
            });
            g.bench_function(BenchmarkId::new("triangulate", &id), |b| {
                b.iter(|| {
                    liemesh::triangulate::triangulate(black_box(&samples), true, true).unwrap()
                })
            });
            g.bench_function(BenchmarkId::new("end_to_end", &id), |b| {
                b.iter(|| liemesh::run(black_box(&field), &params).unwrap())
            });
            let chart: Vec<spade::Point2<f64>> = liemesh::triangulate::chart_points(&samples)
                .into_iter()
                .map(|[x, y]| spade::Point2::new(x, y))
                .collect();
            g.bench_function(BenchmarkId::new("spade_bulk_load", &id), |b| {
                b.iter(|| {
                    spade::DelaunayTriangulation::<spade::Point2<f64>>::bulk_load(black_box(
                        chart.clone(),
                    ))
                    .unwrap()
                })
            });
        }
    }
    g.finish();
}

fn scalars(c: &mut Criterion) {
    let mut g = configure(c, "fig6_sampling");
    let inv = Preset::Fig6.invariant();
    let params = Preset::Fig6.params();
    let f64_field = LieField::<f64>::new(&inv);
    let n = liemesh::sample::sample(&f64_field, &params)
        .unwrap()
        .points
        .len();
    g.throughput(Throughput::Elements(n as u64));
    let f32_field = LieField::<f32>::new(&inv);
    g.bench_function("f32", |b| {
        b.iter(|| liemesh::sample::sample(black_box(&f32_field), &params).unwrap())
    });
    g.bench_function("f64", |b| {
        b.iter(|| liemesh::sample::sample(black_box(&f64_field), &params).unwrap())
    });
    let dual_field = LieField::<Dual<f64>>::new(&inv);
    g.bench_function("dual_f64", |b| {
        b.iter(|| liemesh::sample::sample(black_box(&dual_field), &params).unwrap())
    });
    #[cfg(feature = "mpfr")]
    {
        use liemesh::scalar::Mpfr;
        let m64 = LieField::<Mpfr<64>>::new(&inv);
        g.bench_function("mpfr64", |b| {
            b.iter(|| liemesh::sample::sample(black_box(&m64), &params).unwrap())
        });
        let m256 = LieField::<Mpfr<256>>::new(&inv);
        g.bench_function("mpfr256", |b| {
            b.iter(|| liemesh::sample::sample(black_box(&m256), &params).unwrap())
        });
    }
    g.finish();
}

fn fidelity(c: &mut Criterion) {
    let mut g = configure(c, "fidelity");
    for (ellipsoid, label) in [(false, "sphere"), (true, "ellipsoid")] {
        let found = workloads::fidelity_scan(ellipsoid, workloads::FIDELITY_MAX_TRIANGLES).unwrap();
        assert!(found.reached, "{label}: {found:?}");
        let field = LieField::<f64>::new(&found.invariant);
        g.throughput(Throughput::Elements(found.triangles as u64));
        g.bench_function(label, |b| {
            b.iter(|| liemesh::generate(black_box(&field), &found.params).unwrap())
        });
    }
    g.finish();
}

fn validate(c: &mut Criterion) {
    let mut g = configure(c, "validate");
    g.sampling_mode(SamplingMode::Flat)
        .measurement_time(Duration::from_secs(5));
    for (ellipsoid, label) in [(false, "sphere"), (true, "ellipsoid")] {
        let (inv, params) = workload(ellipsoid, 100_000);
        let field = LieField::<f64>::new(&inv);
        let mesh = liemesh::run(&field, &params).unwrap().mesh;
        let v = mesh.validate();
        assert!(v.is_closed(), "{label}: {v}");
        // The ratio at a glance (best of five each), before criterion's own measurements.
        let best = |f: &mut dyn FnMut()| {
            (0..5)
                .map(|_| {
                    let t = std::time::Instant::now();
                    f();
                    t.elapsed().as_secs_f64()
                })
                .fold(f64::INFINITY, f64::min)
        };
        let meshing = best(&mut || {
            black_box(liemesh::run(&field, &params).unwrap());
        });
        let validation = best(&mut || {
            black_box(mesh.validate());
        });
        eprintln!(
            "validate/{label}-1e5: {} triangles, validation {:.1} ms, meshing {:.1} ms, ratio {:.2}",
            mesh.triangles.len(),
            validation * 1e3,
            meshing * 1e3,
            validation / meshing
        );
        g.throughput(Throughput::Elements(mesh.triangles.len() as u64));
        let id = format!("{label}-1e5");
        g.bench_function(BenchmarkId::new("validate", &id), |b| {
            b.iter(|| black_box(&mesh).validate())
        });
        g.bench_function(BenchmarkId::new("mesh", &id), |b| {
            b.iter(|| liemesh::run(black_box(&field), &params).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, presets, sizes, scalars, fidelity, validate);
criterion_main!(benches);
