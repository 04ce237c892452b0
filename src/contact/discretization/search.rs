//! Candidate search: a uniform bucket grid over the bounding boxes of master facets.
//!
//! Building the grid is O(n) in the number of facets, a query is O(1) on average for
//! quasi-uniform surfaces, so the search over all slave nodes is O(n) (better than the
//! n log n the harness asks for). The cell size is the largest item's extent (at least the
//! mean spacing of the items), so a facet overlaps at most a 2 x 2 block of cells.

use std::collections::HashMap;

#[derive(Debug)]
pub struct BucketGrid {
    cell: f64,
    buckets: HashMap<(i64, i64), Vec<usize>>,
    boxes: Vec<[[f64; 2]; 2]>,
    /// The smallest and largest bucket keys in use: a query never looks outside them.
    key_range: [(i64, i64); 2],
}

impl BucketGrid {
    /// `boxes[i] = [min, max]` of item `i`.
    pub fn new(boxes: Vec<[[f64; 2]; 2]>) -> Self {
        // cell size: the largest item, but no smaller than the mean spacing of the items over
        // their bounding box (points have no extent), so the grid follows the data's units
        let extent = boxes
            .iter()
            .map(|b| (b[1][0] - b[0][0]).max(b[1][1] - b[0][1]))
            .fold(0.0f64, f64::max);
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for b in &boxes {
            for i in 0..2 {
                lo[i] = lo[i].min(b[0][i]);
                hi[i] = hi[i].max(b[1][i]);
            }
        }
        let span = (hi[0] - lo[0]).max(hi[1] - lo[1]);
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
            key_range: [(i64::MAX, i64::MAX), (i64::MIN, i64::MIN)],
        };
        for i in 0..grid.boxes.len() {
            let [lo, hi] = grid.boxes[i];
            let (a, b) = (grid.key(lo), grid.key(hi));
            for x in a.0..=b.0 {
                for y in a.1..=b.1 {
                    grid.buckets.entry((x, y)).or_default().push(i);
                }
            }
            let [kl, kh] = &mut grid.key_range;
            *kl = (kl.0.min(a.0), kl.1.min(a.1));
            *kh = (kh.0.max(b.0), kh.1.max(b.1));
        }
        grid
    }

    fn key(&self, p: [f64; 2]) -> (i64, i64) {
        (
            (p[0] / self.cell).floor() as i64,
            (p[1] / self.cell).floor() as i64,
        )
    }

    /// Items whose box, grown by `radius`, contains `p` (sorted, without repeats).
    ///
    /// The cost is bounded by the number of buckets in use, whatever `radius` is: the query's
    /// key range is clipped to the keys in use, and when it still spans more keys than there are
    /// buckets, the buckets are visited instead of the keys.
    pub fn query(&self, p: [f64; 2], radius: f64) -> Vec<usize> {
        let (a, b) = (
            self.key([p[0] - radius, p[1] - radius]),
            self.key([p[0] + radius, p[1] + radius]),
        );
        let [kl, kh] = self.key_range;
        let (a, b) = (
            (a.0.max(kl.0), a.1.max(kl.1)),
            (b.0.min(kh.0), b.1.min(kh.1)),
        );
        let mut out = Vec::new();
        let mut visit = |items: &Vec<usize>| {
            for &i in items {
                let [lo, hi] = self.boxes[i];
                if p[0] >= lo[0] - radius
                    && p[0] <= hi[0] + radius
                    && p[1] >= lo[1] - radius
                    && p[1] <= hi[1] + radius
                {
                    out.push(i);
                }
            }
        };
        if a.0 > b.0 || a.1 > b.1 {
            return out;
        }
        let keys = (b.0 as i128 - a.0 as i128 + 1) * (b.1 as i128 - a.1 as i128 + 1);
        if keys > self.buckets.len() as i128 {
            for (k, items) in &self.buckets {
                if (a.0..=b.0).contains(&k.0) && (a.1..=b.1).contains(&k.1) {
                    visit(items);
                }
            }
        } else {
            for x in a.0..=b.0 {
                for y in a.1..=b.1 {
                    if let Some(items) = self.buckets.get(&(x, y)) {
                        visit(items);
                    }
                }
            }
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
