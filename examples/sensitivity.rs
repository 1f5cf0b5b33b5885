//! Vertex sensitivities with dual numbers: mesh the ellipsoid of the linear invariant
//! `[1, 4, 16, 0, 0, 0]` with `λ3` as the dual variable, and compare d(vertex)/d(λ3) with a
//! finite difference of two f64 meshes.
//!
//! Run with `cargo run --release --example sensitivity`.

use liemesh::model::{Invariant, LieField};
use liemesh::preset::Preset;
use liemesh::{run, Provenance};
use std::collections::HashMap;

/// Points are matched across runs by (chart angle bits, step); only keys that occur once in
/// a run identify a point.
fn unique_keys(prov: &[Provenance]) -> HashMap<(u64, u32), usize> {
    let mut count: HashMap<(u64, u32), (usize, usize)> = HashMap::new();
    for (i, pr) in prov.iter().enumerate() {
        count
            .entry((pr.theta.to_bits(), pr.step))
            .or_insert((0, i))
            .0 += 1;
    }
    count
        .into_iter()
        .filter(|(_, (n, _))| *n == 1)
        .map(|(k, (_, i))| (k, i))
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let numbers = [1.0, 4.0, 16.0, 0.0, 0.0, 0.0];
    let invariant = Invariant::from_numbers(&numbers)?;
    let mut params = Preset::Fig3.params();
    params.p0 = [0.0, 0.0, 0.25];
    params.dt = Some(0.05);

    // λ3 is number 2 of the 18-number layout.
    let dual = run(&LieField::<f64>::seeded(&invariant, 2), &params)?;
    let h = 1e-6;
    let mut bumped = numbers;
    bumped[2] += h;
    let plus = run(
        &LieField::<f64>::new(&Invariant::from_numbers(&bumped)?),
        &params,
    )?;

    let theirs = unique_keys(&plus.samples.provenance);
    let mine = unique_keys(&dual.samples.provenance);
    println!("ellipsoid [1, 4, 16, 0, 0, 0], p0 = (0, 0, 0.25): d(vertex)/d(λ3)");
    println!(
        "{:>6} {:>40} {:>40}",
        "point", "dual", "finite difference (h = 1e-6)"
    );
    let mut worst: f64 = 0.0;
    let mut compared = 0;
    for (i, (d, pr)) in dual
        .samples
        .points
        .iter()
        .zip(&dual.samples.provenance)
        .enumerate()
    {
        let key = (pr.theta.to_bits(), pr.step);
        if !mine.contains_key(&key) {
            continue;
        }
        let Some(&j) = theirs.get(&key) else {
            continue;
        };
        let p = &plus.samples.points[j];
        let eps = [d[0].eps, d[1].eps, d[2].eps];
        let fd = [0, 1, 2].map(|k| (p[k] - d[k].re) / h);
        for k in 0..3 {
            worst = worst.max((fd[k] - eps[k]).abs());
        }
        if compared < 8 && i % 50 == 0 {
            println!(
                "{i:>6} {:>40} {:>40}",
                format!("({:+.5}, {:+.5}, {:+.5})", eps[0], eps[1], eps[2]),
                format!("({:+.5}, {:+.5}, {:+.5})", fd[0], fd[1], fd[2]),
            );
        }
        compared += 1;
    }
    println!("{compared} points matched; largest |dual - finite difference| = {worst:.2e}");
    if compared < 100 || worst >= 1e-4 {
        return Err(format!("sensitivities disagree: {compared} points, {worst:e}").into());
    }
    Ok(())
}
