//! Plain `[f64; 3]` vector arithmetic for the geometric tests that run on `f64` copies of the
//! points (sampling, triangulation, quality), and a fast hasher for their integer keys.

/// `a − b`.
#[inline]
pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a · b`.
#[inline]
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b`.
#[inline]
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a / |a|` (callers make sure `a` is not zero).
#[inline]
pub(crate) fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

/// Whether the angle between `a` and `b` exceeds the angle whose cosine is `limit_cos`:
/// `a·b < limit_cos |a| |b|`, without an arc cosine. False when either vector is zero or
/// not finite.
#[inline]
pub(crate) fn wider_than(a: [f64; 3], b: [f64; 3], limit_cos: f64) -> bool {
    let norms = (dot(a, a) * dot(b, b)).sqrt();
    norms > 0.0 && norms.is_finite() && dot(a, b) < limit_cos * norms
}

/// `|a − b|`.
#[inline]
pub(crate) fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(d, d).sqrt()
}

/// The signed angle from `p` to `q` about the line through the two points `axis`, in
/// radians in (−π, π], counter-clockwise seen from `axis[1]` looking back at `axis[0]`: the
/// turn of a loop round the axis is the sum over its edges.
pub(crate) fn turn_about([o, far]: [[f64; 3]; 2], p: [f64; 3], q: [f64; 3]) -> f64 {
    let unit = normalize(sub(far, o));
    let across = |x: [f64; 3]| {
        let d = sub(x, o);
        let h = dot(d, unit);
        [d[0] - h * unit[0], d[1] - h * unit[1], d[2] - h * unit[2]]
    };
    let (p, q) = (across(p), across(q));
    dot(cross(p, q), unit).atan2(dot(p, q))
}

/// The hasher of the tables keyed by small integers (vertex pairs, grid cells): rustc-hash's
/// `FxBuildHasher`. SipHash, the standard one, dominated the profiles of those tables.
///
/// It replaced a hand-written multiply-mix hasher, measured against it on the whole pipeline
/// (`liemesh bench --memory-probe`, one thread, CPU time, runs interleaved on a loaded
/// two-core machine): sphere and ellipsoid at 10^5 triangles 219 and 280 ms against 220 and
/// 277 ms (medians of 40 runs each), at 10^6 1.88 and 2.86 s against 1.93 and 3.08 s
/// (medians of 8); 0.16 % fewer instructions (callgrind, 10^5). Not slower, so the
/// maintained crate. Either hasher gives the same meshes, bit for bit (the tables are never
/// iterated in hash order where the order reaches the output).
pub(crate) type FastHash = rustc_hash::FxBuildHasher;
