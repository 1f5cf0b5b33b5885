//! Derivatives of every vertex with respect to an invariant number
//! ([`liemesh::differentiate`]): forward-mode AD through the whole `f64` pipeline, against
//! central differences of whole meshes computed in `Mpfr<256>` with the same discrete
//! decisions.
//!
//! "The same decisions": the central difference uses the `f64` run's automatic lengths
//! ([`liemesh::Resolved::explicit`]), vertices are matched across the three meshes by the
//! sample point they come from (curve and step), and a vertex is compared where the triangles
//! within [`RINGS`] edges of it are the same in all three meshes and its position agrees to
//! 1e-12 (so no other decision, such as a relaxation move taken back, went another way there).
//! The sampler and the triangulation decide on `f64` positions, which in an `Mpfr<256>` run
//! differ from the `f64` run's in the last bit, so a tie may go the other way: a curve
//! inserted a little earlier (which renumbers the points after it), or a cocircular
//! quadrilateral split the other way, around which relaxation then moves the vertices
//! differently.
#![cfg(feature = "mpfr")]

use liemesh::model::{Invariant, LieField};
use liemesh::preset::Preset;
use liemesh::scalar::{Mpfr, Scalar};
use liemesh::{differentiate, Mesh, MeshParams, MeshRun};
use std::collections::{BTreeSet, HashMap, HashSet};

/// Rings of triangles around a vertex that must agree: relaxation's three sweeps reach three
/// rings, and one more covers the flips after it.
const RINGS: usize = 4;

/// The `Mpfr<256>` mesh with layout number `index` moved by `delta` (exactly, in MPFR).
fn shifted(
    inv: &Invariant,
    index: usize,
    delta: &Mpfr<256>,
    params: &MeshParams,
) -> MeshRun<Mpfr<256>> {
    let mut numbers = inv.parameters::<Mpfr<256>>();
    numbers[index] += delta.clone();
    let field = LieField::from_parameters(&numbers, inv.reading());
    liemesh::run(&field, params).expect("Mpfr<256> run")
}

/// A sample point: the curve and step a vertex comes from.
type Key = (u32, u32);

/// Each vertex's sample point, or `None` where two vertices share one (vertices the
/// stitching or refinement added): those are not matched across meshes.
fn keys(mesh: &Mesh) -> Vec<Option<Key>> {
    let all: Vec<Key> = mesh.provenance.iter().map(|p| (p.curve, p.step)).collect();
    let mut count: HashMap<Key, usize> = HashMap::new();
    for k in &all {
        *count.entry(*k).or_default() += 1;
    }
    all.iter().map(|k| (count[k] == 1).then_some(*k)).collect()
}

/// A triangle by its corners' sample points, turned so that the least comes first; a corner
/// that matches nothing is named by its index in `mesh` past every sample point, so that no
/// triangle with one can agree with another mesh's.
fn canonical(t: &[u32; 3], keys: &[Option<Key>]) -> [Key; 3] {
    let k = t.map(|v| keys[v as usize].unwrap_or((u32::MAX, v)));
    let m = (0..3).min_by_key(|&i| k[i]).unwrap_or(0);
    [k[m], k[(m + 1) % 3], k[(m + 2) % 3]]
}

/// For every vertex of `mesh`, the triangles within `RINGS` edges of it.
fn neighbourhoods(mesh: &Mesh, keys: &[Option<Key>]) -> Vec<BTreeSet<[Key; 3]>> {
    let n = mesh.vertices.len();
    let mut around: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            around[v as usize].push(t);
        }
    }
    (0..n)
        .map(|v| {
            let mut seen: HashSet<u32> = HashSet::from([v as u32]);
            let mut frontier = vec![v as u32];
            let mut tris = BTreeSet::new();
            for _ in 0..RINGS {
                let mut next = Vec::new();
                for &u in &frontier {
                    for &t in &around[u as usize] {
                        let tri = mesh.triangles[t];
                        tris.insert(canonical(&tri, keys));
                        for w in tri {
                            if seen.insert(w) {
                                next.push(w);
                            }
                        }
                    }
                }
                frontier = next;
            }
            tris
        })
        .collect()
}

/// Checks `d(vertex)/d(number index)` against the `Mpfr<256>` central difference where the
/// decisions agree; returns how many vertices were compared.
fn check(inv: &Invariant, index: usize, params: &MeshParams) -> usize {
    // The automatic lengths follow the field at p0: every run uses the f64 run's.
    let params = &liemesh::run(&LieField::<f64>::new(inv), params)
        .unwrap()
        .params
        .explicit();
    let d = differentiate(&LieField::<f64>::seeded(inv, index), params).unwrap();
    let h = Mpfr::<256>::exp2i(-80);
    let plus = shifted(inv, index, &h, params);
    let minus = shifted(inv, index, &-h.clone(), params);
    let (keys_d, keys_plus, keys_minus) = (keys(&d.mesh), keys(&plus.mesh), keys(&minus.mesh));
    let (around, around_plus, around_minus) = (
        neighbourhoods(&d.mesh, &keys_d),
        neighbourhoods(&plus.mesh, &keys_plus),
        neighbourhoods(&minus.mesh, &keys_minus),
    );
    // Where each sample point is in the MPFR meshes.
    let where_is = |keys: &[Option<Key>]| -> HashMap<Key, usize> {
        keys.iter()
            .enumerate()
            .filter_map(|(i, k)| k.map(|k| (k, i)))
            .collect()
    };
    let (in_plus, in_minus) = (where_is(&keys_plus), where_is(&keys_minus));
    let two_h = h.clone() + h.clone();
    let (mut worst, mut largest, mut compared) = (0.0_f64, 0.0_f64, 0);
    let apart = |a: [f64; 3], b: [f64; 3]| (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max);
    for (i, dv) in d.d_vertices.iter().enumerate() {
        let Some(key) = keys_d[i] else { continue };
        let (Some(&ip), Some(&im)) = (in_plus.get(&key), in_minus.get(&key)) else {
            continue;
        };
        if around[i] != around_plus[ip] || around[i] != around_minus[im] {
            continue;
        }
        // A decision the triangles do not show (a relaxation move taken back, a clamped
        // step) moves the vertex by far more than rounding.
        let here = d.mesh.vertices[i];
        if apart(here, plus.mesh.vertices[ip]) > 1e-12
            || apart(here, minus.mesh.vertices[im]) > 1e-12
        {
            continue;
        }
        compared += 1;
        for (k, ad) in dv.iter().enumerate() {
            let cd = ((plus.vertices[ip][k].clone() - minus.vertices[im][k].clone())
                / two_h.clone())
            .to_f64();
            worst = worst.max((ad - cd).abs());
            largest = largest.max(cd.abs());
        }
    }
    let n = d.d_vertices.len();
    let relative = worst / largest.max(1e-300);
    assert!(largest > 0.0, "the mesh does not depend on number {index}");
    assert!(
        relative <= 1e-9,
        "number {index}: max |AD − CD| = {worst:e}, relative {relative:e} over {compared} of {n} vertices"
    );
    // Ties are rare: most of the mesh is decided alike.
    assert!(
        2 * compared >= n,
        "only {compared} of {n} vertices decided alike"
    );
    compared
}

#[test]
fn fig3_and_fig6_vertex_derivatives_match_mpfr_central_differences() {
    // fig3 in the paper mode (no relaxation: every vertex is a sample point), and fig6 (the
    // Hamiltonian invariant) in the default mode. The unit sphere in the default mode is not
    // differentiable in λ: every point is an umbilic, so the principal directions the step
    // control follows jump under any perturbation.
    let mut paper = Preset::Fig3.params();
    paper.mode = liemesh::Mode::Paper;
    let n = check(&Preset::Fig3.invariant(), 1, &paper);
    assert!(n > 0);
    check(&Preset::Fig6.invariant(), 0, &Preset::Fig6.params());
    check(&Preset::Fig6.invariant(), 7, &Preset::Fig6.params());
}

#[cfg(feature = "toml")]
#[test]
fn an_invariant_files_vertex_derivatives_match_mpfr_central_differences() {
    let file = liemesh::io::invariant_file::InvariantFile::read(std::path::Path::new(
        "examples/surfaces/ellipsoid.toml",
    ))
    .unwrap();
    // λ3, and the first angle (a non-zero angle makes the field non-integrable; the
    // derivative at zero is still well defined).
    check(&file.invariant, 2, &file.params);
    check(&file.invariant, 3, &file.params);
}
