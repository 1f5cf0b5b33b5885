//! Tangential relaxation on the surface (default mode).
//!
//! Each interior vertex moves towards the centroid of its neighbours, but along the surface:
//! the move is a drift-free chord step of [`trace::step_fixed`] in the working precision, so
//! the vertices stay exactly on the level set of an integrable field, dual numbers keep their
//! derivatives, and MPFR runs stay comparable with `f64` ones. `p0` and boundary vertices stay
//! where they are. Edge flips afterwards restore the surface Delaunay property.

use super::flip::flip_to_surface_delaunay;
use super::Mesh;
use crate::params::MeshParams;
use crate::sample::Samples;
use crate::scalar::{Scalar, Vec3};
use crate::trace::{self, StepConfig};
use crate::NormalField;

/// Relaxation sweeps; three take the worst angles from the sampler's ~19° to above 20°
/// on the presets and the ellipsoid while moving vertices by a fraction of a step.
const SWEEPS: usize = 3;
/// Fraction of the way to the neighbours' centroid moved per sweep.
const DAMPING: f64 = 0.5;

/// Relaxes `mesh` (whose vertices are `samples` points, found by provenance) and returns the
/// vertices in the working precision.
pub(crate) fn relax<T: Scalar, F: NormalField<T>>(
    field: &F,
    params: &MeshParams,
    samples: &Samples<T>,
    mesh: &mut Mesh,
) -> Vec<Vec3<T>> {
    let n = mesh.vertices.len();
    let mut pos: Vec<Vec3<T>> = mesh
        .provenance
        .iter()
        .map(|pr| {
            let i = samples.curves[pr.curve as usize].points[pr.step as usize] as usize;
            samples.points[i].clone()
        })
        .collect();
    // Neighbours, sorted for a deterministic sum; boundary vertices are fixed.
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut edge_uses = std::collections::HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            neighbours[a as usize].push(b);
            *edge_uses.entry((a.min(b), a.max(b))).or_insert(0u32) += 1;
        }
    }
    let mut fixed = vec![false; n];
    for (&(a, b), &uses) in &edge_uses {
        if uses != 2 {
            fixed[a as usize] = true;
            fixed[b as usize] = true;
        }
    }
    for (v, pr) in mesh.provenance.iter().enumerate() {
        if pr.curve == 0 && pr.step == 0 {
            fixed[v] = true;
        }
    }
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
    }
    let cfg = StepConfig::<T>::new(params);
    let damping = T::from_f64(DAMPING);
    for _ in 0..SWEEPS {
        let moved: Vec<Vec3<T>> = (0..n)
            .map(|v| {
                if fixed[v] || neighbours[v].is_empty() {
                    return pos[v].clone();
                }
                let mut c = Vec3::<T>::zero();
                for &u in &neighbours[v] {
                    c = &c + &pos[u as usize];
                }
                let c = c.scale(&(T::one() / T::from_f64(neighbours[v].len() as f64)));
                let d = &c - &pos[v];
                let len = d.norm() * damping.clone();
                if len.partial_cmp(&T::zero()) != Some(std::cmp::Ordering::Greater) {
                    return pos[v].clone();
                }
                trace::step_fixed(field, &cfg, &pos[v], &d, &len).unwrap_or_else(|_| pos[v].clone())
            })
            .collect();
        pos = moved;
    }
    mesh.vertices = pos.iter().map(|p| p.to_f64()).collect();
    mesh.normals = pos
        .iter()
        .map(|p| {
            trace::unit_normal(field, p)
                .map(|(_, n, _)| n.to_f64())
                .unwrap_or([0.0; 3])
        })
        .collect();
    let budget = 8 * mesh.triangles.len() + 64;
    flip_to_surface_delaunay(&mesh.vertices, &mesh.normals, &mut mesh.triangles, budget);
    pos
}
