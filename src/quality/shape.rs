//! Triangle shape: angles, radius-edge ratios, edge lengths.

use crate::triangulate::Mesh;

/// Shape statistics of a mesh's triangles (angles in degrees).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Shape {
    /// Smallest angle of any triangle.
    pub min_angle: f64,
    /// 1st percentile of the triangles' smallest angles.
    pub min_angle_p1: f64,
    /// Mean of the triangles' smallest angles.
    pub min_angle_mean: f64,
    /// Largest angle of any triangle.
    pub max_angle: f64,
    /// Largest circumradius ÷ shortest edge (1/√3 ≈ 0.577 for an equilateral triangle).
    pub radius_edge_max: f64,
    /// Mean circumradius ÷ shortest edge.
    pub radius_edge_mean: f64,
    /// Shortest edge.
    pub edge_min: f64,
    /// Longest edge.
    pub edge_max: f64,
    /// Mean edge length.
    pub edge_mean: f64,
    /// Standard deviation of edge lengths ÷ mean.
    pub edge_cv: f64,
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The three angles (degrees) of the triangle with side lengths opposite each corner.
pub(crate) fn angles(p: [[f64; 3]; 3]) -> [f64; 3] {
    let a = dist(p[1], p[2]);
    let b = dist(p[2], p[0]);
    let c = dist(p[0], p[1]);
    let angle = |opp: f64, s1: f64, s2: f64| {
        ((s1 * s1 + s2 * s2 - opp * opp) / (2.0 * s1 * s2))
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees()
    };
    [angle(a, b, c), angle(b, c, a), angle(c, a, b)]
}

impl Shape {
    /// Measures `mesh` (an empty mesh gives all zeros).
    pub fn of(mesh: &Mesh) -> Shape {
        let n = mesh.triangles.len();
        if n == 0 {
            return Shape::default();
        }
        let mut mins = Vec::with_capacity(n);
        let (mut max_angle, mut re_max, mut re_sum) = (0.0_f64, 0.0_f64, 0.0);
        for t in &mesh.triangles {
            let p = t.map(|i| mesh.vertices[i as usize]);
            let ang = angles(p);
            let mn = ang.iter().copied().fold(f64::INFINITY, f64::min);
            mins.push(if mn.is_nan() { 0.0 } else { mn });
            max_angle = max_angle.max(ang.iter().copied().fold(0.0, f64::max));
            let e = [dist(p[1], p[2]), dist(p[2], p[0]), dist(p[0], p[1])];
            let shortest = e.iter().copied().fold(f64::INFINITY, f64::min);
            // Circumradius R = a / (2 sin A) with the largest angle for accuracy.
            let (k, _) = ang
                .iter()
                .enumerate()
                .fold((0, -1.0), |m, (i, &x)| if x > m.1 { (i, x) } else { m });
            let r = e[k] / (2.0 * ang[k].to_radians().sin());
            let ratio = if shortest > 0.0 && r.is_finite() {
                r / shortest
            } else {
                f64::INFINITY
            };
            re_max = re_max.max(ratio);
            re_sum += ratio;
        }
        let mut sorted = mins.clone();
        sorted.sort_by(f64::total_cmp);
        let mut edges: Vec<f64> = Vec::with_capacity(3 * n / 2 + 3);
        let mut seen = std::collections::HashSet::with_capacity(3 * n / 2 + 3);
        for t in &mesh.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if seen.insert((a.min(b), a.max(b))) {
                    edges.push(dist(mesh.vertices[a as usize], mesh.vertices[b as usize]));
                }
            }
        }
        let mean = edges.iter().sum::<f64>() / edges.len() as f64;
        let var = edges.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / edges.len() as f64;
        Shape {
            min_angle: sorted[0],
            min_angle_p1: sorted[(n - 1) / 100],
            min_angle_mean: mins.iter().sum::<f64>() / n as f64,
            max_angle,
            radius_edge_max: re_max,
            radius_edge_mean: re_sum / n as f64,
            edge_min: edges.iter().copied().fold(f64::INFINITY, f64::min),
            edge_max: edges.iter().copied().fold(0.0, f64::max),
            edge_mean: mean,
            edge_cv: var.sqrt() / mean,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_equilateral_triangle_has_sixty_degree_angles() {
        let h = 3f64.sqrt() / 2.0;
        let m = Mesh {
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, h, 0.0]],
            normals: vec![[0.0, 0.0, 1.0]; 3],
            triangles: vec![[0, 1, 2]],
            provenance: vec![Default::default(); 3],
        };
        let s = Shape::of(&m);
        assert!((s.min_angle - 60.0).abs() < 1e-9 && (s.max_angle - 60.0).abs() < 1e-9);
        assert!((s.radius_edge_max - 1.0 / 3f64.sqrt()).abs() < 1e-12);
        assert!(s.edge_cv < 1e-12);
    }
}
