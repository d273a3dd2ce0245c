//! Vectorised reductions over one pixel's column of window sums (the disparity axis): the best
//! cost, its first index, the cost-curve range and the count under the uniqueness bound. Written as fixed-size
//! lane accumulators with branch-free selects, because `Iterator::min` and early-exit searches
//! compile to one element at a time.

use super::params::MAX_DISPARITIES;

/// `0, 1, 2, …` as `i16`: zipping with this instead of `enumerate` keeps index reductions in
/// 16-bit lanes, so they vectorise eight or sixteen wide.
static INDEX: [i16; MAX_DISPARITIES as usize] = {
    let mut index = [0i16; MAX_DISPARITIES as usize];
    let mut i = 0;
    while i < index.len() {
        index[i] = i as i16;
        i += 1;
    }
    index
};

/// Lanes of the explicit reductions below: fixed-size accumulator arrays that the compiler maps
/// to SIMD registers (an `Iterator::min` folds one element at a time).
const LANES: usize = 16;

/// The smallest value (`i16::MAX` for an empty slice).
#[inline]
pub(super) fn min_value(values: &[i16]) -> i16 {
    let mut acc = [i16::MAX; LANES];
    let chunks = values.chunks_exact(LANES);
    let rest = chunks.remainder();
    for chunk in chunks {
        for k in 0..LANES {
            acc[k] = acc[k].min(chunk[k]);
        }
    }
    acc.iter().chain(rest).copied().fold(i16::MAX, i16::min)
}

/// Lanes of `scan_column`: one SSE register of `i16` per accumulator, so its five
/// accumulators stay in registers.
const SCAN_LANES: usize = 8;

/// "No index" in the lane accumulators below.
const NONE: i16 = i16::MAX;

/// Lane accumulators of `scan_column`.
struct ScanLanes {
    best: [i16; SCAN_LANES],
    low: [i16; SCAN_LANES],
    high: [i16; SCAN_LANES],
    under: [i16; SCAN_LANES],
}

impl ScanLanes {
    fn new() -> Self {
        Self {
            best: [NONE; SCAN_LANES],
            low: [NONE; SCAN_LANES],
            high: [-1; SCAN_LANES],
            under: [0; SCAN_LANES],
        }
    }

    /// One chunk; `(best_cost, range_threshold, unique_bound)`. Padding lanes carry the cost
    /// `i16::MAX`, which no threshold accepts (thresholds are clamped below it or equal to the
    /// best cost, itself far below it).
    #[inline(always)]
    fn step(&mut self, c: &[i16; SCAN_LANES], index: &[i16; SCAN_LANES], t: (i16, i16, i16)) {
        for k in 0..SCAN_LANES {
            let (c, i) = (c[k], index[k]);
            let is_best = i16::from(c == t.0).wrapping_neg();
            let in_range = i16::from(c <= t.1).wrapping_neg();
            let rival = i16::from(c < t.2).wrapping_neg();
            self.best[k] = self.best[k].min((i & is_best) | (NONE & !is_best));
            self.low[k] = self.low[k].min((i & in_range) | (NONE & !in_range));
            self.high[k] = self.high[k].max((i & in_range) | !in_range);
            self.under[k] = self.under[k].wrapping_sub(rival);
        }
    }
}

/// What one pass over a pixel's cost column finds.
pub(super) struct ColumnScan {
    /// First index of the best cost.
    pub best: usize,
    /// First index within the range threshold.
    pub low: usize,
    /// Last index within the range threshold.
    pub high: usize,
    /// How many costs lie strictly under the uniqueness bound.
    pub under_bound: usize,
}

/// Finds, in one vectorised pass, the first index of `best_cost`, the span of costs at most
/// `range_threshold` and how many costs lie under `unique_bound`. The selects are branch-free
/// (all-ones masks) so that the loop runs sixteen lanes at a time.
#[inline]
pub(super) fn scan_column(
    column: &[i16],
    best_cost: i16,
    range_threshold: i16,
    unique_bound: i16,
) -> ColumnScan {
    let mut acc = ScanLanes::new();
    let chunks = column.chunks_exact(SCAN_LANES);
    let rest = chunks.remainder();
    let thresholds = (best_cost, range_threshold, unique_bound);
    for (chunk, index) in chunks.zip(INDEX.chunks_exact(SCAN_LANES)) {
        // Fixed-size copies: the compiler then knows the trip count and vectorises.
        let chunk: &[i16; SCAN_LANES] = chunk.try_into().unwrap_or(&[NONE; SCAN_LANES]);
        let index: &[i16; SCAN_LANES] = index.try_into().unwrap_or(&[NONE; SCAN_LANES]);
        acc.step(chunk, index, thresholds);
    }
    if !rest.is_empty() {
        // Pad the tail with a cost that no threshold accepts.
        let mut chunk = [NONE; SCAN_LANES];
        chunk[..rest.len()].copy_from_slice(rest);
        let tail = column.len() - rest.len();
        let mut index = [NONE; SCAN_LANES];
        index[..rest.len()].copy_from_slice(&INDEX[tail..tail + rest.len()]);
        acc.step(&chunk, &index, thresholds);
    }
    let ScanLanes {
        best,
        low,
        high,
        under,
    } = acc;
    let min = |a: &[i16; SCAN_LANES]| a.iter().copied().fold(NONE, i16::min);
    let max = |a: &[i16; SCAN_LANES]| a.iter().copied().fold(-1, i16::max);
    let best = min(&best).max(0) as usize;
    let under_bound = under.iter().map(|&n| n as usize).sum();
    ColumnScan {
        best,
        low: (min(&low) as usize).min(best),
        high: (max(&high).max(0) as usize).max(best),
        under_bound,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_matches_a_plain_search() {
        // Lengths around the lane width, with ties and a distant near-tie.
        for len in [1usize, 7, 8, 9, 16, 17, 80] {
            let column: Vec<i16> = (0..len)
                .map(|i| ((i * 37 + 11) % 23) as i16 + if i == len / 2 { -20 } else { 0 })
                .collect();
            let best_cost = min_value(&column);
            assert_eq!(best_cost, *column.iter().min().unwrap());
            let scan = scan_column(&column, best_cost, best_cost + 5, best_cost + 3);
            let best = column.iter().position(|&c| c == best_cost).unwrap();
            assert_eq!(scan.best, best);
            assert_eq!(
                scan.low,
                column.iter().position(|&c| c <= best_cost + 5).unwrap()
            );
            assert_eq!(
                scan.high,
                column.iter().rposition(|&c| c <= best_cost + 5).unwrap()
            );
            let under = column.iter().filter(|&&c| c < best_cost + 3).count();
            assert_eq!(scan.under_bound, under);
        }
        assert_eq!(min_value(&[]), i16::MAX);
    }
}
