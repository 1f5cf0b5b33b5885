//! The finished mesh: what every stage after triangulation reads, and what the samples' provenance is recorded in.
//!
//! [`Mesh::validate`] checks any mesh for validity (manifold, oriented, non-degenerate,
//! embedded) with exact predicates and reports what it found as a [`Validation`].

mod validate;
pub use validate::{Offenders, Validation, MAX_EXAMPLES};

/// The validation of `mesh` and its boundary edges, as `(low, high)` vertex pairs in order.
pub(crate) fn validate_with_boundary(mesh: &Mesh) -> (Validation, Vec<(u32, u32)>) {
    let listed = validate::validate_listing(&mesh.vertices, &mesh.triangles);
    (listed.validation, listed.boundary)
}

/// Every self-intersecting pair of faces (lower index first, in order), decided exactly.
pub(crate) fn crossings(p: &[[f64; 3]], tris: &[[u32; 3]]) -> Vec<(usize, usize)> {
    validate::validate_listing_crossings(p, tris).1
}

/// Where a vertex came from in the sampling stage.
///
/// `curve` and `step` identify the integral curve and the accepted step on it
/// (`step == 0` is the curve's first point; the initial point `p0` is curve 0,
/// step 0). `s` is the arc length along the polyline of the curve measured from
/// `p0` (inserted curves inherit the arc length of the point they start from),
/// and `theta` is the curve's angle at `p0` in the chart, in radians.
/// Vertices added to close a surface carry `curve == u32::MAX`
/// ([`Provenance::CLOSING_CURVE`]); vertices added by refinement carry
/// [`Provenance::REFINED_CURVE`], the round that added them as `step`, and the arc length and
/// angle of the vertex their chord started from. Vertices read from a file that does not
/// record provenance (OBJ; PLY without a `curve` property) carry
/// [`Provenance::UNKNOWN_CURVE`]: nothing is claimed about where they came from.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Provenance {
    /// Index of the integral curve the vertex lies on.
    pub curve: u32,
    /// Index of the accepted step on that curve (0 = the curve's first point).
    pub step: u32,
    /// Arc length from `p0` along the sampled curves.
    pub s: f64,
    /// The curve's angle at `p0` (chart angle), radians.
    pub theta: f64,
}

impl Provenance {
    /// Curve id given to vertices that were added to close a surface.
    pub const CLOSING_CURVE: u32 = u32::MAX;
    /// Curve id given to vertices that refinement to a normal-error bound added.
    pub const REFINED_CURVE: u32 = u32::MAX - 1;
    /// Curve id of vertices whose origin is unknown: read from a file that does not record
    /// it (see [`Provenance::UNKNOWN`]).
    pub const UNKNOWN_CURVE: u32 = u32::MAX - 2;
    /// The provenance of a vertex read from a file that records none (an OBJ file, a PLY file
    /// without provenance properties): curve [`Provenance::UNKNOWN_CURVE`], and `step`, `s`
    /// and `theta` zero.
    pub const UNKNOWN: Provenance = Provenance {
        curve: Self::UNKNOWN_CURVE,
        step: 0,
        s: 0.0,
        theta: 0.0,
    };
}

/// A triangle mesh in `f64`: vertices, unit field normals at the vertices,
/// counter-clockwise triangles (seen from the side the field normal points to)
/// and per-vertex [`Provenance`].
///
/// All four vectors describing vertices have the same length, and every index
/// in `triangles` is smaller than it.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Mesh {
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Unit normal of the field at each vertex.
    pub normals: Vec<[f64; 3]>,
    /// Triangles as vertex index triples, counter-clockwise about the field normal.
    pub triangles: Vec<[u32; 3]>,
    /// Where each vertex came from.
    pub provenance: Vec<Provenance>,
}

impl Mesh {
    /// The triangles, each rotated to start at its smallest vertex index (orientation kept),
    /// sorted: two meshes with the same triangles compare equal however each triangle's
    /// listing starts and in whatever order the triangles come (what a determinism or
    /// precision comparison of two runs compares).
    ///
    /// ```
    /// use liemesh::Mesh;
    ///
    /// let mut a = Mesh::default();
    /// a.triangles = vec![[2, 0, 1], [3, 1, 0]];
    /// let mut b = a.clone();
    /// b.triangles = vec![[0, 3, 1], [0, 1, 2]];
    /// assert_eq!(a.canonical_triangles(), [[0, 1, 2], [0, 3, 1]]);
    /// assert_eq!(a.canonical_triangles(), b.canonical_triangles());
    /// ```
    pub fn canonical_triangles(&self) -> Vec<[u32; 3]> {
        let mut v: Vec<[u32; 3]> = self
            .triangles
            .iter()
            .map(|t| {
                let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
                [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
            })
            .collect();
        v.sort_unstable();
        v
    }
}

/// The octahedron with corners ±x, ±y, ±z (vertices 0..6 = +x, −x, +y, −y, +z, −z), faces
/// counter-clockwise seen from outside: the smallest closed mesh for unit tests.
#[cfg(test)]
pub(crate) fn octahedron() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let vertices = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let triangles = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    (vertices, triangles)
}
