//! Order-preserving parallel maps that stay on the calling thread when the work is small.
//!
//! Handing work to rayon's workers costs tens of microseconds and, while the workers wait
//! for more, some of a busy machine's time, so each map runs in parallel only from `min`
//! items up, where the work takes milliseconds. Either way the results come back in index
//! order and are the same: the callers map pure functions.
//!
//! Without the `parallel` feature (no rayon) every map runs on the calling thread; the results
//! are the same, bit for bit.

#[cfg(feature = "parallel")]
use rayon::prelude::*;

/// Items from which a map of cheap work (tens of nanoseconds each: a face test) goes parallel.
pub(crate) const MIN_CHEAP: usize = 16_384;
/// Items from which a map of costly work (microseconds each: field evaluations) goes parallel;
/// the presets (at most about 1,100 vertices) stay on one thread.
pub(crate) const MIN_COSTLY: usize = 2048;

/// `(0..n).map(f).collect()`, in parallel when `n >= min`.
pub(crate) fn map<R: Send>(n: usize, min: usize, f: impl Fn(usize) -> R + Sync + Send) -> Vec<R> {
    #[cfg(feature = "parallel")]
    if n >= min {
        return (0..n).into_par_iter().map(f).collect();
    }
    #[cfg(not(feature = "parallel"))]
    let _ = min;
    (0..n).map(f).collect()
}

/// Calls `f(i, &mut items[i])` for every item, in parallel when there are at least `min`.
pub(crate) fn for_each_mut<X: Send>(
    items: &mut [X],
    min: usize,
    f: impl Fn(usize, &mut X) + Sync + Send,
) {
    #[cfg(feature = "parallel")]
    if items.len() >= min {
        items.par_iter_mut().enumerate().for_each(|(i, x)| f(i, x));
        return;
    }
    #[cfg(not(feature = "parallel"))]
    let _ = min;
    items.iter_mut().enumerate().for_each(|(i, x)| f(i, x));
}

/// Runs `a` and `b`, side by side when rayon is there; returns both results.
pub(crate) fn join<A: Send, B: Send>(
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    #[cfg(feature = "parallel")]
    return rayon::join(a, b);
    #[cfg(not(feature = "parallel"))]
    (a(), b())
}

#[cfg(test)]
mod tests {
    #[test]
    fn parallel_and_sequential_maps_agree_and_keep_the_order() {
        let f = |i: usize| (i * 7919) % 1009;
        assert_eq!(super::map(5000, 1, f), super::map(5000, usize::MAX, f));
        let mut a = vec![0usize; 5000];
        super::for_each_mut(&mut a, 1, |i, x| *x = f(i));
        assert_eq!(a, super::map(5000, usize::MAX, f));
    }
}
