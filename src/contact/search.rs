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
        };
        for i in 0..grid.boxes.len() {
            let [lo, hi] = grid.boxes[i];
            let (a, b) = (grid.key(lo), grid.key(hi));
            for x in a.0..=b.0 {
                for y in a.1..=b.1 {
                    grid.buckets.entry((x, y)).or_default().push(i);
                }
            }
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
    pub fn query(&self, p: [f64; 2], radius: f64) -> Vec<usize> {
        let (a, b) = (
            self.key([p[0] - radius, p[1] - radius]),
            self.key([p[0] + radius, p[1] + radius]),
        );
        let mut out = Vec::new();
        for x in a.0..=b.0 {
            for y in a.1..=b.1 {
                if let Some(items) = self.buckets.get(&(x, y)) {
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
}
