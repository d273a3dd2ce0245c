//! The least rate of a cost field, kept exact while its voxels change.
//!
//! A* scales its distance heuristic by the least cost per metre of any voxel
//! ([`CostField::min_rate`](super::CostField::min_rate)). Scanning the region for it after every
//! update would cost an update as much as reading every voxel once, so the field keeps the least
//! rate with the number of voxels that have it: a change that lowers a rate below it, or moves a
//! voxel to or away from it, adjusts both, and only when the last voxel with the least rate
//! leaves it does the field scan again.

/// The least rate over a field's voxels and how many voxels have exactly that rate.
///
/// Invariant: `value` is at most every voxel's rate, and `count` voxels have rate `value`;
/// `count == 0` means `value` is only a lower bound (the field must scan again).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct LeastRate {
    value: f32,
    count: usize,
}

impl LeastRate {
    /// The least rate of `items` (rates are never NaN) and how many have it; infinity for no
    /// items. (Eight running minima, so that the loop vectorises.)
    pub(super) fn scan<T>(items: &[T], rate: impl Fn(&T) -> f32) -> Self {
        let mut lanes = [f32::INFINITY; 8];
        let chunks = items.chunks_exact(8);
        let rest = chunks.remainder();
        for chunk in chunks {
            for (lane, item) in lanes.iter_mut().zip(chunk) {
                let r = rate(item);
                *lane = if r < *lane { r } else { *lane };
            }
        }
        let value = lanes
            .iter()
            .copied()
            .chain(rest.iter().map(&rate))
            .fold(f32::INFINITY, |a, b| if b < a { b } else { a });
        let count = items.iter().filter(|item| rate(item) == value).count();
        Self { value, count }
    }

    /// The least rate (a lower bound while [`LeastRate::is_lost`]).
    pub(super) fn value(self) -> f32 {
        self.value
    }

    /// Whether no voxel has the least rate any more, so that it must be found again.
    pub(super) fn is_lost(self) -> bool {
        self.count == 0
    }

    /// One voxel's rate went from `old` to `new`.
    #[inline]
    pub(super) fn replace(&mut self, old: f32, new: f32) {
        if old == new {
            return;
        }
        if new < self.value {
            // Every other voxel's rate is at least the old least rate, above `new`.
            *self = Self {
                value: new,
                count: 1,
            };
        } else if new == self.value {
            self.count += 1;
        } else if old == self.value {
            self.count = self.count.saturating_sub(1);
        }
    }

    /// Adds the changes that workers recorded against this least rate (each voxel changed by
    /// at most one worker).
    pub(super) fn merge(&mut self, tallies: impl Iterator<Item = RateTally>) {
        let (mut below, mut at_below, mut joined, mut left) = (self.value, 0, 0, 0);
        for t in tallies {
            if t.below < below {
                (below, at_below) = (t.below, t.at_below);
            } else if t.below == below && below < self.value {
                at_below += t.at_below;
            }
            joined += t.joined;
            left += t.left;
        }
        if below < self.value {
            *self = Self {
                value: below,
                count: at_below,
            };
        } else {
            self.count = (self.count + joined).saturating_sub(left);
        }
    }
}

/// Rate changes one worker saw, against the least rate `least` of the field before them.
#[derive(Clone, Copy, Debug)]
pub(super) struct RateTally {
    least: f32,
    /// The lowest new rate below `least` (or `least`), and how many voxels took it.
    below: f32,
    at_below: usize,
    /// Voxels that moved to `least` from another rate, and away from it.
    joined: usize,
    left: usize,
}

impl RateTally {
    /// No changes yet, against the field's least rate `least`.
    pub(super) fn new(least: LeastRate) -> Self {
        Self {
            least: least.value,
            below: least.value,
            at_below: 0,
            joined: 0,
            left: 0,
        }
    }

    /// One voxel's rate went from `old` to `new`.
    #[inline]
    pub(super) fn record(&mut self, old: f32, new: f32) {
        if old == new {
            return;
        }
        if new < self.below {
            (self.below, self.at_below) = (new, 1);
        } else if new == self.below && new < self.least {
            self.at_below += 1;
        }
        if new == self.least {
            self.joined += 1;
        }
        if old == self.least {
            self.left += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Applies random rate changes to a field of rates, half sequentially and half through
    /// tallies, and checks the kept least rate against a scan after every round.
    #[test]
    fn kept_least_rate_matches_a_scan() {
        let mut rates: Vec<f32> = (0..64).map(|i| 1.0 + (i % 5) as f32).collect();
        let mut least = LeastRate::scan(&rates, |r| *r);
        let mut state = 7u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as usize
        };
        let values = [1.0, 1.5, 2.0, 3.0, f32::INFINITY, 0.5];
        for round in 0..2000 {
            // Workers: disjoint halves of the voxels, each voxel changed at most once.
            let mut tallies = [RateTally::new(least), RateTally::new(least)];
            let first = next() % rates.len();
            for k in 0..next() % 6 {
                let i = (first + 11 * k) % rates.len();
                let new = values[next() % values.len()].max(if round % 3 == 0 { 0.0 } else { 1.0 });
                tallies[i % 2].record(rates[i], new);
                rates[i] = new;
            }
            least.merge(tallies.into_iter());
            for _ in 0..next() % 4 {
                let i = next() % rates.len();
                let new = values[next() % values.len()];
                least.replace(rates[i], new);
                rates[i] = new;
            }
            if least.is_lost() {
                least = LeastRate::scan(&rates, |r| *r);
            }
            assert_eq!(least, LeastRate::scan(&rates, |r| *r), "round {round}");
        }
    }
}
