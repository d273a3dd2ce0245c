//! Vectorised reductions over one pixel's column of window sums (the disparity axis): the first
//! index of the least sum, the cost-curve range and the count under the uniqueness bound.
//! Written as fixed-size lane accumulators with branch-free selects, because `Iterator::min`
//! and early-exit searches compile to one element at a time.

use super::params::MAX_DISPARITIES;

/// `0, 1, 2, …` as `i16`: zipping with this instead of `enumerate` keeps index reductions in
/// 16-bit lanes, so they vectorise eight wide.
static INDEX: [i16; MAX_DISPARITIES as usize] = {
    let mut index = [0i16; MAX_DISPARITIES as usize];
    let mut i = 0;
    while i < index.len() {
        index[i] = i as i16;
        i += 1;
    }
    index
};

/// `MAX_DISPARITIES - i`, all positive: the largest `REVERSE[i]` over a set of indices marks
/// the first of them, so a first-index search is a `max` reduction like a last-index one.
static REVERSE: [i16; MAX_DISPARITIES as usize] = {
    let mut reverse = [0i16; MAX_DISPARITIES as usize];
    let mut i = 0;
    while i < reverse.len() {
        reverse[i] = (MAX_DISPARITIES as usize - i) as i16;
        i += 1;
    }
    reverse
};

/// Lanes of `scan_column`: two SSE registers of `i16` per accumulator. (With eight lanes the
/// compiler vectorises across chunks instead, with costly shuffles.)
const SCAN_LANES: usize = 16;

/// A value no threshold accepts, for padding.
#[cfg(test)]
const NONE: i16 = i16::MAX;

/// The largest lane, by halving (shuffles and `pmaxsw` rather than a scalar chain).
#[inline(always)]
fn max_lane(mut a: [i16; SCAN_LANES]) -> i16 {
    let mut half = SCAN_LANES / 2;
    while half > 0 {
        for k in 0..half {
            a[k] = a[k].max(a[k + half]);
        }
        half /= 2;
    }
    a[0]
}

/// The sum of the lanes, by halving.
#[inline(always)]
fn sum_lane(mut a: [i16; SCAN_LANES]) -> i16 {
    let mut half = SCAN_LANES / 2;
    while half > 0 {
        for k in 0..half {
            a[k] = a[k].wrapping_add(a[k + half]);
        }
        half /= 2;
    }
    a[0]
}

/// The smallest lane, by halving (`N` a power of two).
#[inline(always)]
pub(super) fn min_lane<const N: usize>(mut a: [i16; N]) -> i16 {
    let mut half = N / 2;
    while half > 0 {
        for k in 0..half {
            a[k] = a[k].min(a[k + half]);
        }
        half /= 2;
    }
    a[0]
}

/// Lane accumulators of `scan_column`, all maxima so that every update is an `and` and a
/// `pmaxsw`: first indices as [`REVERSE`] values (0 = none yet), last indices as [`INDEX`]
/// values, and the count of rivals.
struct ScanLanes {
    first_best: [i16; SCAN_LANES],
    first_low: [i16; SCAN_LANES],
    last_high: [i16; SCAN_LANES],
    under: [i16; SCAN_LANES],
}

impl ScanLanes {
    /// One chunk; `(best_cost, range_threshold, unique_bound)`. Padding lanes carry the cost
    /// `NONE`, which no threshold accepts (thresholds are clamped below it or equal to the
    /// best cost, itself far below it).
    #[inline(always)]
    fn step(
        &mut self,
        c: &[i16; SCAN_LANES],
        index: &[i16; SCAN_LANES],
        reverse: &[i16; SCAN_LANES],
        t: (i16, i16, i16),
    ) {
        for k in 0..SCAN_LANES {
            let c = c[k];
            let is_best = i16::from(c == t.0).wrapping_neg();
            let in_range = i16::from(c <= t.1).wrapping_neg();
            self.first_best[k] = self.first_best[k].max(reverse[k] & is_best);
            self.first_low[k] = self.first_low[k].max(reverse[k] & in_range);
            self.last_high[k] = self.last_high[k].max(index[k] & in_range);
            self.under[k] = self.under[k].wrapping_add(i16::from(c < t.2));
        }
    }
}

/// What a scan of a pixel's column of window sums finds (small enough to come back in
/// registers).
pub(super) struct ColumnScan {
    /// The least sum.
    pub best_cost: i16,
    /// Its first index.
    pub best: u16,
    /// First index within the range threshold.
    pub low: u16,
    /// Last index within the range threshold.
    pub high: u16,
    /// The uniqueness bound for this best cost.
    pub unique_bound: i16,
    /// How many sums lie strictly under the uniqueness bound.
    pub under_bound: u16,
}

/// Whether any of the sixteen lanes is at most `t`; compiles to one `pmovmskb` test.
#[inline(always)]
fn any_at_most(c: &[i16; SCAN_LANES], t: i16) -> bool {
    let mut any = false;
    for &v in c {
        any |= v <= t;
    }
    any
}

/// Scans a pixel's column of window sums: the least sum and its first index, then, with the
/// thresholds `thresholds[best]` = (range threshold, uniqueness bound), the span of sums at most
/// the range threshold and how many lie under the uniqueness bound. `column.len()` must be a
/// multiple of [`SCAN_LANES`] (a remainder is ignored): callers pad with `i16::MAX`, which no
/// threshold accepts.
///
/// Only chunks of sixteen sums with one at or under a threshold can change the answer; the
/// others (most of them: the thresholds are close to the least sum) are skipped after one
/// vector test. The chunks that count go through branch-free lane accumulators (all-ones
/// masks). Not inlined: the compiler vectorises it reliably only on its own.
#[inline(never)]
pub(super) fn scan_column(column: &[i16], best_cost: i16, thresholds: &[(i16, i16)]) -> ColumnScan {
    let (range_threshold, unique_bound) = thresholds
        .get(best_cost.max(0) as usize)
        .copied()
        .unwrap_or((best_cost, 0));
    let mut acc = ScanLanes {
        first_best: [0; SCAN_LANES],
        first_low: [0; SCAN_LANES],
        last_high: [0; SCAN_LANES],
        under: [0; SCAN_LANES],
    };
    let wanted = range_threshold.max(unique_bound.saturating_sub(1));
    let tables = INDEX
        .chunks_exact(SCAN_LANES)
        .zip(REVERSE.chunks_exact(SCAN_LANES));
    for (chunk, (index, reverse)) in column.chunks_exact(SCAN_LANES).zip(tables) {
        // Fixed-size views: the compiler then knows the trip count and vectorises.
        let (Ok(chunk), Ok(index), Ok(reverse)) = (
            <&[i16; SCAN_LANES]>::try_from(chunk),
            <&[i16; SCAN_LANES]>::try_from(index),
            <&[i16; SCAN_LANES]>::try_from(reverse),
        ) else {
            continue;
        };
        if any_at_most(chunk, wanted) {
            acc.step(
                chunk,
                index,
                reverse,
                (best_cost, range_threshold, unique_bound),
            );
        }
    }
    // Reduced lane by lane with shuffles (an iterator `sum` or `max` here compiles to a
    // scalar chain).
    let (first_best, first_low) = (max_lane(acc.first_best), max_lane(acc.first_low));
    let (last_high, under) = (max_lane(acc.last_high), sum_lane(acc.under));
    let first = |reverse: i16| (MAX_DISPARITIES as i16).wrapping_sub(reverse) as u16;
    let best = if first_best > 0 { first(first_best) } else { 0 };
    let low = if first_low > 0 {
        first(first_low)
    } else {
        best
    };
    ColumnScan {
        best_cost,
        best,
        low: low.min(best),
        high: (last_high.max(0) as u16).max(best),
        unique_bound,
        under_bound: under.max(0) as u16,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_matches_a_plain_search() {
        // Lengths around the lane width, with ties and a distant near-tie.
        for len in [1usize, 7, 8, 9, 16, 17, 80] {
            let mut column: Vec<i16> = (0..len)
                .map(|i| ((i * 37 + 11) % 23) as i16 + if i == len / 2 { 0 } else { 20 })
                .collect();
            // Padded to whole chunks, as the matcher does.
            column.resize(len.next_multiple_of(SCAN_LANES), NONE);
            let best_cost = *column.iter().min().unwrap();
            // Range threshold best + 5, uniqueness bound best + 3.
            let thresholds: Vec<(i16, i16)> = (0..100).map(|b| (b + 5, b + 3)).collect();
            let scan = scan_column(&column, best_cost, &thresholds);
            assert_eq!(scan.best_cost, best_cost);
            let best = column.iter().position(|&c| c == best_cost).unwrap();
            assert_eq!(usize::from(scan.best), best);
            assert_eq!(
                usize::from(scan.low),
                column.iter().position(|&c| c <= best_cost + 5).unwrap()
            );
            assert_eq!(
                usize::from(scan.high),
                column.iter().rposition(|&c| c <= best_cost + 5).unwrap()
            );
            let under = column.iter().filter(|&&c| c < best_cost + 3).count();
            assert_eq!(usize::from(scan.under_bound), under);
        }
    }
}
