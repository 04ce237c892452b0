//! Candidate search: a uniform bucket grid over the bounding boxes of items (master facets or
//! nodes) in `D` dimensions (2 or 3; one code path).
//!
//! Building the grid is O(n) in the number of items, a query is O(1) on average for
//! quasi-uniform surfaces, so the search over all slave nodes is O(n) (better than the
//! n log n the harness asks for). The cell size is the largest item's extent (at least the
//! mean spacing of the items), so an item overlaps at most a 2 x 2 (x 2) block of cells.

use std::collections::HashMap;

#[derive(Debug)]
pub struct BucketGrid<const D: usize = 2> {
    cell: f64,
    buckets: HashMap<[i64; D], Vec<usize>>,
    boxes: Vec<[[f64; D]; 2]>,
    /// The smallest and largest bucket keys in use: a query never looks outside them.
    key_range: [[i64; D]; 2],
}

/// Calls `visit` with every key of the box `lo..=hi` (inclusive in every component; none
/// when some `lo[i] > hi[i]`).
fn for_each_key<const D: usize>(lo: [i64; D], hi: [i64; D], mut visit: impl FnMut([i64; D])) {
    if (0..D).any(|i| lo[i] > hi[i]) {
        return;
    }
    let mut key = lo;
    loop {
        visit(key);
        // odometer: advance the first component that has room, reset those before it
        let mut i = 0;
        loop {
            if i == D {
                return;
            }
            if key[i] < hi[i] {
                key[i] += 1;
                break;
            }
            key[i] = lo[i];
            i += 1;
        }
    }
}

impl<const D: usize> BucketGrid<D> {
    /// `boxes[i] = [min, max]` of item `i`.
    pub fn new(boxes: Vec<[[f64; D]; 2]>) -> Self {
        // cell size: the largest item, but no smaller than the mean spacing of the items over
        // their bounding box (points have no extent), so the grid follows the data's units
        let extent = boxes
            .iter()
            .map(|b| {
                (0..D)
                    .map(|i| b[1][i] - b[0][i])
                    .fold(f64::NEG_INFINITY, f64::max)
            })
            .fold(0.0f64, f64::max);
        let (mut lo, mut hi) = ([f64::INFINITY; D], [f64::NEG_INFINITY; D]);
        for b in &boxes {
            for i in 0..D {
                lo[i] = lo[i].min(b[0][i]);
                hi[i] = hi[i].max(b[1][i]);
            }
        }
        let span = (0..D)
            .map(|i| hi[i] - lo[i])
            .fold(f64::NEG_INFINITY, f64::max);
        let spacing = if boxes.is_empty() || !span.is_finite() {
            0.0
        } else {
            span / boxes.len() as f64
        };
        let cell = extent.max(spacing);
        let cell = if cell > 0.0 { cell } else { 1.0 };
        let mut grid = BucketGrid {
            cell,
            buckets: HashMap::new(),
            boxes,
            key_range: [[i64::MAX; D], [i64::MIN; D]],
        };
        for i in 0..grid.boxes.len() {
            let [lo, hi] = grid.boxes[i];
            let (a, b) = (grid.key(lo), grid.key(hi));
            let buckets = &mut grid.buckets;
            for_each_key(a, b, |k| buckets.entry(k).or_default().push(i));
            let [kl, kh] = &mut grid.key_range;
            for d in 0..D {
                kl[d] = kl[d].min(a[d]);
                kh[d] = kh[d].max(b[d]);
            }
        }
        grid
    }

    fn key(&self, p: [f64; D]) -> [i64; D] {
        p.map(|x| (x / self.cell).floor() as i64)
    }

    /// The box `[lo, hi]` of item `i`.
    pub fn item_box(&self, i: usize) -> [[f64; D]; 2] {
        self.boxes[i]
    }

    /// Items whose box, grown by `radius`, contains `p` (sorted, without repeats).
    ///
    /// The cost is bounded by the number of buckets in use, whatever `radius` is: the query's
    /// key range is clipped to the keys in use, and when it still spans more keys than there are
    /// buckets, the buckets are visited instead of the keys.
    pub fn query(&self, p: [f64; D], radius: f64) -> Vec<usize> {
        let (a, b) = (
            self.key(p.map(|x| x - radius)),
            self.key(p.map(|x| x + radius)),
        );
        let [kl, kh] = self.key_range;
        let mut a = a;
        let mut b = b;
        for d in 0..D {
            a[d] = a[d].max(kl[d]);
            b[d] = b[d].min(kh[d]);
        }
        let mut out = Vec::new();
        let mut visit = |items: &Vec<usize>| {
            for &i in items {
                let [lo, hi] = self.boxes[i];
                if (0..D).all(|d| p[d] >= lo[d] - radius && p[d] <= hi[d] + radius) {
                    out.push(i);
                }
            }
        };
        if (0..D).any(|d| a[d] > b[d]) {
            return out;
        }
        let keys: i128 = (0..D).map(|d| b[d] as i128 - a[d] as i128 + 1).product();
        if keys > self.buckets.len() as i128 {
            for (k, items) in &self.buckets {
                if (0..D).all(|d| (a[d]..=b[d]).contains(&k[d])) {
                    visit(items);
                }
            }
        } else {
            for_each_key(a, b, |k| {
                if let Some(items) = self.buckets.get(&k) {
                    visit(items);
                }
            });
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn query_matches_brute_force() {
        let boxes: Vec<[[f64; 2]; 2]> = (0..200)
            .map(|i| {
                let x = (i as f64 * 0.731).sin() * 10.0;
                let y = (i as f64 * 0.377).cos() * 10.0;
                [[x, y], [x + 0.3 + 0.2 * (i % 3) as f64, y + 0.1]]
            })
            .collect();
        let grid = BucketGrid::new(boxes.clone());
        for k in 0..50 {
            let p = [(k as f64 * 1.3).sin() * 10.0, (k as f64 * 0.9).cos() * 10.0];
            let r = 0.4;
            let brute: Vec<usize> = (0..boxes.len())
                .filter(|&i| {
                    let [lo, hi] = boxes[i];
                    p[0] >= lo[0] - r && p[0] <= hi[0] + r && p[1] >= lo[1] - r && p[1] <= hi[1] + r
                })
                .collect();
            assert_eq!(grid.query(p, r), brute);
        }
    }

    /// A deterministic pseudo-random sequence in [0, 1) (a linear congruential generator).
    fn uniform(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Random boxes (some of them points) and queries in `D` dimensions against the brute
    /// force over all boxes.
    fn random_boxes_match_brute_force<const D: usize>(seed: u64) {
        let mut state = seed;
        let boxes: Vec<[[f64; D]; 2]> = (0..400)
            .map(|k| {
                let lo: [f64; D] = std::array::from_fn(|_| 20.0 * uniform(&mut state) - 10.0);
                let size: [f64; D] = std::array::from_fn(|_| {
                    if k % 5 == 0 {
                        0.0
                    } else {
                        1.5 * uniform(&mut state)
                    }
                });
                [lo, std::array::from_fn(|i| lo[i] + size[i])]
            })
            .collect();
        let grid = BucketGrid::new(boxes.clone());
        for _ in 0..300 {
            let p: [f64; D] = std::array::from_fn(|_| 24.0 * uniform(&mut state) - 12.0);
            let r = 2.0 * uniform(&mut state);
            let brute: Vec<usize> = (0..boxes.len())
                .filter(|&i| {
                    let [lo, hi] = boxes[i];
                    (0..D).all(|d| p[d] >= lo[d] - r && p[d] <= hi[d] + r)
                })
                .collect();
            assert_eq!(grid.query(p, r), brute, "query at {p:?}, radius {r}");
        }
    }

    #[test]
    fn random_boxes_in_2d_and_3d_match_brute_force() {
        random_boxes_match_brute_force::<2>(7);
        random_boxes_match_brute_force::<3>(11);
        random_boxes_match_brute_force::<3>(12345);
    }

    #[test]
    fn a_huge_radius_costs_no_more_than_the_buckets() {
        let boxes: Vec<[[f64; 2]; 2]> = (0..100)
            .map(|i| [[i as f64, 0.0], [i as f64 + 1.0, 0.0]])
            .collect();
        let grid = BucketGrid::new(boxes);
        // At 9aead84 these visited (2r / cell)^2 keys: minutes at 1e4, never ending at 1e308.
        for r in [1e4, 1e12, 1e308, f64::INFINITY] {
            assert_eq!(grid.query([50.0, 3.0], r), (0..100).collect::<Vec<_>>());
        }
        assert!(grid.query([50.0, 300.0], 1.0).is_empty());
    }
}
