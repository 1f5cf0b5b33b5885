//! Compressed rows: values filed under small integer keys (vertex → triangles, cell →
//! faces) in two flat arrays, by a counting sort, instead of a list or a hash table per key.

/// Files `entries` — `(row, value)` pairs, read twice — under their rows: row `r`'s values,
/// in the order of `entries`, are `list[start[r]..start[r + 1]]`. Returns `(start, list)`, or
/// `None` if a row is not below `rows`.
pub(crate) fn compressed_rows<I>(rows: usize, entries: I) -> Option<(Vec<u32>, Vec<u32>)>
where
    I: Iterator<Item = (usize, u32)> + Clone,
{
    let mut start = vec![0u32; rows + 1];
    for (r, _) in entries.clone() {
        *start.get_mut(r + 1)? += 1;
    }
    for r in 0..rows {
        start[r + 1] += start[r];
    }
    let mut fill: Vec<u32> = start[..rows].to_vec();
    let mut list = vec![0u32; start[rows] as usize];
    for (r, value) in entries {
        list[fill[r] as usize] = value;
        fill[r] += 1;
    }
    Some((start, list))
}

/// Rows by vertex, in triangle order: `value(t, k)` for every corner `k` of every triangle
/// `t`, filed under the corner's vertex ([`compressed_rows`]). `None` if a corner is not
/// below `vertices`.
pub(crate) fn rows_by_corner(
    triangles: &[[u32; 3]],
    vertices: usize,
    value: impl Fn(usize, usize) -> u32,
) -> Option<(Vec<u32>, Vec<u32>)> {
    let entries = triangles.iter().enumerate().flat_map(|(t, tr)| {
        let value = &value;
        (0..3).map(move |k| (tr[k] as usize, value(t, k)))
    });
    compressed_rows(vertices, entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_keep_the_order_of_their_entries() {
        let entries = [(2, 10), (0, 11), (2, 12), (0, 13)];
        let (start, list) = compressed_rows(3, entries.iter().copied()).unwrap();
        assert_eq!(start, [0, 2, 2, 4]);
        assert_eq!(list, [11, 13, 10, 12]);
        assert!(compressed_rows(2, entries.iter().copied()).is_none());
    }

    #[test]
    fn corners_are_filed_under_their_vertices() {
        let tris = [[0, 1, 2], [2, 1, 3]];
        let (start, list) = rows_by_corner(&tris, 4, |t, k| (3 * t + k) as u32).unwrap();
        assert_eq!(start, [0, 1, 3, 5, 6]);
        assert_eq!(list, [0, 1, 4, 2, 3, 5]);
        assert!(rows_by_corner(&tris, 3, |_, _| 0).is_none());
    }
}
