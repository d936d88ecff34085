//! Per-kernel and whole-step throughput at small sizes (criterion). CI runs these with a
//! short measurement time only to prove they still run; the figures that matter come from
//! `grains bench` on the dense bed.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::model::{contact_force, Bodies, ContactForce, Geometry, History, KickWindow, Kinematics};
use grains::real::{Real, Vec3};
use grains::scene::{self, Scene};
use std::hint::black_box;
use std::path::Path;

fn scene(name: &str) -> Scene {
    scene::load(Path::new(&format!("scenes/{name}.toml"))).expect("bundled scene")
}

/// The pair kernel's contact maths alone: one Hertz-Mindlin contact with history.
fn pair_maths<T: Real>(c: &mut Criterion, label: &str) {
    let s = scene("pour");
    let model = s.model.cast::<T>();
    let coeffs = s.pair_coeffs::<T>()[0];
    let (r, m) = (T::of(5e-4), T::of(1.4e-6));
    let geo = Geometry::grain_grain(Vec3::new(T::of(9.99e-4), T::ZERO, T::ZERO), T::of(9.99e-4), r, r, m, m);
    let kin = Kinematics { v_i: Vec3::new(T::of(-1e-3), T::of(2e-3), T::ZERO), v_j: Vec3::ZERO, w_i: Vec3::new(T::ZERO, T::ZERO, T::of(3.0)), w_j: Vec3::ZERO };
    let inertia = T::of(0.4) * m * r * r;
    let bodies = Bodies { m_i: m, inertia_i: inertia, m_j: m, inertia_j: inertia, j_is_wall: false };
    let mut group = c.benchmark_group("contact_force");
    group.throughput(Throughput::Elements(1));
    group.bench_function(label, |b| {
        let mut h = History::<T>::default();
        b.iter(|| -> ContactForce<T> { contact_force(&model, &coeffs, black_box(&geo), black_box(&kin), &bodies, &mut h, T::of(2e-6), KickWindow::centred(T::of(2e-6))) })
    });
    group.finish();
}

/// Whole steps and neighbour-list rebuilds of the pour's 3000 falling grains.
fn engine<T: Real>(c: &mut Criterion, label: &str) {
    let s = scene("pour");
    let n = s.grains.len() as u64;
    let mut group = c.benchmark_group("pour_3000");
    group.throughput(Throughput::Elements(n));
    let mut e = CpuEngine::<T>::new(&s).expect("engine");
    group.bench_function(BenchmarkId::new("step", label), |b| b.iter(|| e.step().expect("stable")));
    group.bench_function(BenchmarkId::new("rebuild", label), |b| b.iter(|| e.rebuild().expect("rebuild")));
    group.bench_function(BenchmarkId::new("stats", label), |b| b.iter(|| black_box(e.stats().unwrap())));
    group.finish();
}

fn kernels(c: &mut Criterion) {
    pair_maths::<f64>(c, "f64");
    pair_maths::<f32>(c, "f32");
    engine::<f64>(c, "f64");
    engine::<f32>(c, "f32");
}

criterion_group!(benches, kernels);
criterion_main!(benches);
