//! Vectorised reductions over one pixel's column of window sums (the disparity axis): the first
//! index of the least sum, the cost-curve range and the count under the uniqueness bound.
//! Each chunk of sixteen sums is compared as a vector and turned into a bit mask, and the
//! indices come from scalar bit scans of the masks, because `Iterator::min` and early-exit
//! searches compile to one element at a time.

/// Lanes of `scan_column`: one chunk of `i16` sums per mask.
const SCAN_LANES: usize = 16;

/// A value no threshold accepts, for padding.
#[cfg(test)]
const NONE: i16 = i16::MAX;

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

fuzzyvox_core::dispatched! {
    /// Scans a pixel's column of window sums: the least sum and its first index, then, with the
    /// thresholds `thresholds[best]` = (range threshold, uniqueness bound), the span of sums at most
    /// the range threshold and how many lie under the uniqueness bound. `column.len()` must be a
    /// multiple of [`SCAN_LANES`] (a remainder is ignored): callers pad with `i16::MAX`, which no
    /// threshold accepts.
    ///
    /// Only chunks of sixteen sums with one at or under a threshold can change the answer; the
    /// others (most of them: the thresholds are close to the least sum) are skipped after one
    /// vector test. Compiled for AVX-512 and AVX2 as well, chosen at run time.
    pub(super) fn scan_column(column: &[i16], best_cost: i16, thresholds: &[(i16, i16)]) -> ColumnScan {
        let (range_threshold, unique_bound) = thresholds
            .get(best_cost.max(0) as usize)
            .copied()
            .unwrap_or((best_cost, 0));
        let wanted = range_threshold.max(unique_bound.saturating_sub(1));
        let (mut best, mut low, mut high, mut under) = (None, None, 0u32, 0u32);
        for (base, chunk) in (0u32..)
            .step_by(SCAN_LANES)
            .zip(column.chunks_exact(SCAN_LANES))
        {
            // A fixed-size view: the compiler then knows the trip count and vectorises.
            let Ok(chunk) = <&[i16; SCAN_LANES]>::try_from(chunk) else {
                continue;
            };
            if lane_mask(chunk, |c| c <= wanted) == 0 {
                continue;
            }
            // One bit per lane (`pmovmskb`), then scalar bit scans: no lane reductions.
            let equal = lane_mask(chunk, |c| c == best_cost);
            let in_range = lane_mask(chunk, |c| c <= range_threshold);
            if best.is_none() && equal != 0 {
                best = Some(base + equal.trailing_zeros());
            }
            if in_range != 0 {
                low.get_or_insert(base + in_range.trailing_zeros());
                high = base + 31 - in_range.leading_zeros();
            }
            under += lane_mask(chunk, |c| c < unique_bound).count_ones();
        }
        let best = best.unwrap_or(0) as u16;
        ColumnScan {
            best_cost,
            best,
            low: low.map_or(best, |l| (l as u16).min(best)),
            high: (high as u16).max(best),
            unique_bound,
            under_bound: under as u16,
        }
}
}

/// Bit `k` set when lane `k` passes `test`; compiles to a vector compare and `pmovmskb`.
#[inline(always)]
fn lane_mask(c: &[i16; SCAN_LANES], test: impl Fn(i16) -> bool) -> u32 {
    let mut mask = 0u32;
    for (k, &v) in c.iter().enumerate() {
        mask |= u32::from(test(v)) << k;
    }
    mask
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
