//! Exact accumulation: how the fuzzy map stores a membership so that the same observations give
//! the same map, bit for bit, in any order, split into any partial maps and on any number of
//! threads.
//!
//! A t-conorm is associative and commutative, but its `f32` evaluation is not: `S(S(a, b), c)`
//! and `S(a, S(b, c))` differ in their last bits. So the map does not store memberships. For an
//! Archimedean t-conorm, `S(x, y) = g⁽⁻¹⁾(g(x) + g(y))` with its additive generator `g`, and the
//! map stores each membership as a **level**: `g(μ)` in fixed point, an integer count of steps
//! `δ`. Evidence `e` adds `round(g(e) / δ)` levels, and integer addition is exactly associative;
//! a nilpotent t-conorm (finite `g(1)`) saturates at the level of `g(1)`, a strict one at
//! `u32::MAX`, and a saturating sum of non-negative integers is still associative. A membership
//! is read back as `g⁽⁻¹⁾(level · δ)`, a pure function of the level.
//!
//! The step is `δ = g(½) / 2²⁰`: a membership of one half is 2²⁰ levels, so the fixed point
//! changes a membership by at most `δ / (2 g'(μ))`, about `3 · 10⁻⁷` at `μ = ½` for the
//! probabilistic sum, far below what a class threshold can see (`docs/concepts.md` gives the
//! measured error against an `f64` reference). Evidence smaller than half a step
//! (`g(e) < δ / 2`, below `3 · 10⁻⁷` for the probabilistic sum) is lost. The largest membership a
//! strict t-conorm can hold is `g⁽⁻¹⁾(2³² δ) = g⁽⁻¹⁾(4096 g(½))`: 1 in `f32` for the
//! probabilistic sum, Einstein, Frank, Hamacher with `γ > 0` and Aczél–Alsina with `p <= 2`;
//! below 1 for generators that grow fast (Hamacher `γ = 0`: 0.99976, Aczél–Alsina `p = 3`:
//! 0.999985, Dombi `λ = 2`: 0.985, `λ = 10`: 0.70); [`Accumulator::max_membership`] says it for
//! each operator.
//!
//! The maximum, the drastic sum and the nilpotent maximum have no generator, but each returns
//! one of its inputs or 1, so they are exact as they are: for them the level is the `f32` bit
//! pattern of the membership (monotone for non-negative floats).

use serde::{Deserialize, Serialize};

use crate::measures::Memberships;
use crate::ops::{Family, TConorm, unit};

/// A voxel's two memberships as the fuzzy map stores them: levels of the map's
/// [`Accumulator`] (read them as memberships with [`Accumulator::memberships`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Levels {
    /// The occupied membership's level.
    pub occupied: u32,
    /// The free membership's level.
    pub free: u32,
}

impl Levels {
    /// Both levels in one word (occupied in the high half), the fuzzy map's cell stamp
    /// ([`crate::map::VoxelMap::block_stamps`]).
    #[inline]
    pub fn packed(self) -> u64 {
        (u64::from(self.occupied) << 32) | u64::from(self.free)
    }

    /// The levels of a [`Levels::packed`] word.
    #[inline]
    pub fn unpacked(word: u64) -> Self {
        Self {
            occupied: (word >> 32) as u32,
            free: word as u32,
        }
    }
}

impl crate::storage::CellBits for Levels {
    #[inline]
    fn bits(&self) -> u64 {
        self.packed()
    }
}

/// Levels per `g(½)`: a membership of one half is `2²⁰` levels.
const LEVELS_PER_HALF: f64 = (1u32 << 20) as f64;

/// The lowest level the probabilistic sum reads through [`DecayTables`] (`t = level · δ` about
/// 0.04); below it `1 - e^{-t}` is small and `expm1` keeps its relative precision.
const DECAY_TABLE_FROM: u32 = 1 << 16;

/// `e^{-level · δ}` for the probabilistic sum's step `δ`, as the product of three tables over
/// the level's top 10, middle 11 and low 11 bits: three loads and two multiplications instead
/// of an `exp`, within a few `f64` ulps of it, so that reading a level (which a planner does
/// for every voxel a frame changed) is cheap. A level still reads as a fixed function of
/// itself, whatever the reader.
struct DecayTables {
    step: f64,
    high: Vec<f64>,
    mid: Vec<f64>,
    low: Vec<f64>,
}

impl DecayTables {
    fn new(step: f64) -> Self {
        let table = |bits: u32, shift: u32| -> Vec<f64> {
            (0..1u64 << bits)
                .map(|k| (-((k << shift) as f64) * step).exp())
                .collect()
        };
        Self {
            step,
            high: table(10, 22),
            mid: table(11, 11),
            low: table(11, 0),
        }
    }

    #[inline]
    fn decay(&self, level: u32) -> f64 {
        let l = level as usize;
        self.high[l >> 22] * self.mid[(l >> 11) & 0x7ff] * self.low[l & 0x7ff]
    }
}

/// The probabilistic sum's decay tables, built on first use; `None` for another step (every
/// probabilistic-sum accumulator has the same one).
fn product_decay(step: f64) -> Option<&'static DecayTables> {
    static TABLES: std::sync::OnceLock<DecayTables> = std::sync::OnceLock::new();
    let tables = TABLES.get_or_init(|| DecayTables::new(step));
    (tables.step.to_bits() == step.to_bits()).then_some(tables)
}

/// How a t-conorm's memberships are stored and accumulated as levels (see the module's
/// documentation): exactly, in any order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Accumulator {
    operator: TConorm,
    scale: Scale,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scale {
    /// Fixed point in generator space: `level = round(g(μ) / step)`, saturating at `cap`;
    /// `cap_is_one` when the cap is `g(1)` (a nilpotent t-conorm), so that it reads as 1.
    Generator {
        step: f64,
        cap: u32,
        cap_is_one: bool,
    },
    /// The `f32` bits of the membership, combined with the t-conorm itself.
    Bits,
}

impl Accumulator {
    /// The accumulator of `operator`.
    pub fn new(operator: TConorm) -> Self {
        let half = operator
            .generator(0.5)
            .filter(|g| g.is_finite() && *g > 0.0);
        let scale = match (operator.family(), half) {
            (Family::Minimum | Family::Drastic | Family::NilpotentMinimum, _) | (_, None) => {
                Scale::Bits
            }
            (_, Some(half)) => {
                let step = half / LEVELS_PER_HALF;
                let top = operator.generator(1.0).map_or(f64::INFINITY, |g| g / step);
                if top.is_finite() && top < f64::from(u32::MAX) {
                    Scale::Generator {
                        step,
                        cap: top.round() as u32,
                        cap_is_one: true,
                    }
                } else {
                    Scale::Generator {
                        step,
                        cap: u32::MAX,
                        cap_is_one: false,
                    }
                }
            }
        };
        Self { operator, scale }
    }

    /// The t-conorm.
    pub fn operator(&self) -> TConorm {
        self.operator
    }

    /// The fixed-point step `δ` in generator space, `None` for the t-conorms without a
    /// generator (stored as their `f32` bits).
    pub fn step(&self) -> Option<f64> {
        match self.scale {
            Scale::Generator { step, .. } => Some(step),
            Scale::Bits => None,
        }
    }

    /// The level that stores membership `mu` (clamped into `[0, 1]`, NaN as 0).
    #[inline]
    pub fn level(&self, mu: f32) -> u32 {
        let mu = unit(mu);
        match self.scale {
            Scale::Generator { step, cap, .. } => {
                if mu >= 1.0 {
                    return cap;
                }
                match self.operator.generator(mu) {
                    Some(g) if g.is_finite() => {
                        let level = (g / step).round();
                        if level >= f64::from(cap) {
                            cap
                        } else {
                            level as u32
                        }
                    }
                    _ => cap,
                }
            }
            Scale::Bits => mu.to_bits(),
        }
    }

    /// Whether `level` is one this accumulator can produce: at most the cap in generator space,
    /// or the bits of a membership in `[0, 1]` (files with other levels are damaged).
    pub fn is_valid(&self, level: u32) -> bool {
        match self.scale {
            Scale::Generator { cap, .. } => level <= cap,
            Scale::Bits => (0.0..=1.0).contains(&f32::from_bits(level)),
        }
    }

    /// The membership a level stands for: `g⁽⁻¹⁾(level · δ)`, or the `f32` of its bits.
    #[inline]
    pub fn membership(&self, level: u32) -> f32 {
        match self.scale {
            Scale::Generator {
                step,
                cap,
                cap_is_one,
            } => {
                if level == 0 {
                    0.0
                } else if level >= cap && cap_is_one {
                    1.0
                } else {
                    let level = level.min(cap);
                    match self.operator.family() {
                        // The default operator's inverse, inline: 1 - e^{-t}.
                        Family::Product => match product_decay(step) {
                            Some(tables) if level >= DECAY_TABLE_FROM => {
                                (1.0 - tables.decay(level)).clamp(0.0, 1.0) as f32
                            }
                            _ => (-(-f64::from(level) * step).exp_m1()).clamp(0.0, 1.0) as f32,
                        },
                        _ => self
                            .operator
                            .generator_inverse(f64::from(level) * step)
                            .unwrap_or(0.0),
                    }
                }
            }
            Scale::Bits => unit(f32::from_bits(level)),
        }
    }

    /// Both memberships of a voxel's levels.
    #[inline]
    pub fn memberships(&self, levels: Levels) -> Memberships {
        Memberships {
            occupied: self.membership(levels.occupied),
            free: self.membership(levels.free),
        }
    }

    /// The memberships of many voxels' levels, in order. Neighbouring voxels often hold the
    /// same level (space cleared by the same scans), so each set's last level is read once.
    pub fn memberships_into(&self, levels: &[Levels], out: &mut [Memberships]) {
        // Level 0 reads as 0 for every operator.
        let (mut occupied, mut free) = ((0, 0.0), (0, 0.0));
        for (m, l) in out.iter_mut().zip(levels) {
            if l.occupied != occupied.0 {
                occupied = (l.occupied, self.membership(l.occupied));
            }
            if l.free != free.0 {
                free = (l.free, self.membership(l.free));
            }
            *m = Memberships {
                occupied: occupied.1,
                free: free.1,
            };
        }
    }

    /// Both levels of a voxel's memberships.
    pub fn levels(&self, memberships: Memberships) -> Levels {
        Levels {
            occupied: self.level(memberships.occupied),
            free: self.level(memberships.free),
        }
    }

    /// `S` of two stored memberships, as levels: their saturating sum in generator space, or
    /// the t-conorm of the two memberships for the t-conorms without a generator. Exactly
    /// commutative and associative.
    #[inline]
    pub fn combine(&self, a: u32, b: u32) -> u32 {
        match self.scale {
            Scale::Generator { cap, .. } => a.saturating_add(b).min(cap),
            Scale::Bits => self
                .operator
                .apply(f32::from_bits(a), f32::from_bits(b))
                .to_bits(),
        }
    }

    /// `S(stored, evidence)`: the level after `evidence` (a membership) joins a stored level.
    #[inline]
    pub fn accumulate(&self, level: u32, evidence: f32) -> u32 {
        self.accumulate_level(level, self.evidence_level(evidence))
    }

    /// What `evidence` (a membership) adds: its level, or for the t-conorms without a
    /// generator its `f32` bits.
    #[inline]
    pub fn evidence_level(&self, evidence: f32) -> u32 {
        match self.scale {
            Scale::Generator { .. } => self.level(evidence),
            Scale::Bits => evidence.to_bits(),
        }
    }

    /// [`Accumulator::accumulate`] with the evidence already as
    /// [`Accumulator::evidence_level`].
    #[inline]
    pub fn accumulate_level(&self, level: u32, evidence: u32) -> u32 {
        match self.scale {
            Scale::Generator { .. } => self.combine(level, evidence),
            Scale::Bits => self
                .operator
                .apply(f32::from_bits(level), f32::from_bits(evidence))
                .to_bits(),
        }
    }

    /// The largest membership the map can hold with this operator: 1, except for strict
    /// t-conorms whose generator outgrows the fixed point (see the module's documentation).
    pub fn max_membership(&self) -> f32 {
        match self.scale {
            Scale::Generator { cap, .. } => self.membership(cap),
            Scale::Bits => 1.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The probabilistic sum's table decay reads levels as `expm1` does, to within one `f32`
    /// ulp, and almost always to the bit.
    #[test]
    fn table_decay_reads_as_expm1() {
        let acc = Accumulator::new(TConorm::new(Family::Product).unwrap());
        let Scale::Generator { step, .. } = acc.scale else {
            panic!("the probabilistic sum has a generator")
        };
        let reference = |level: u32| (-(-f64::from(level) * step).exp_m1()).clamp(0.0, 1.0) as f32;
        let (mut state, mut differ, mut total) = (12345u64, 0usize, 0usize);
        let mut levels: Vec<u32> = (0..32).flat_map(|b| [1u32 << b, (1u32 << b) - 1]).collect();
        levels.extend(
            (DECAY_TABLE_FROM - 4..DECAY_TABLE_FROM + 4000).chain(u32::MAX - 4000..=u32::MAX),
        );
        for _ in 0..2_000_000 {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            // Spread over every magnitude: a random level below a random power of two.
            let bits = (state >> 59) as u32;
            levels.push(((state >> 16) as u32) >> bits);
        }
        for level in levels {
            let (fast, slow) = (acc.membership(level), reference(level));
            total += 1;
            if fast.to_bits() != slow.to_bits() {
                differ += 1;
                assert!(
                    fast.to_bits().abs_diff(slow.to_bits()) <= 1,
                    "level {level}: {fast} vs {slow}"
                );
            }
        }
        assert!(
            differ * 100_000 < total,
            "{differ} of {total} levels read differently"
        );
        eprintln!("{differ} of {total} levels read one ulp apart");
    }

    fn accumulators() -> Vec<Accumulator> {
        [
            "product",
            "max",
            "lukasiewicz",
            "drastic",
            "nilpotent",
            "einstein",
            "hamacher:0",
            "hamacher:0.5",
            "yager:2",
            "yager:0.5",
            "frank:3",
            "dombi:2",
            "schweizer-sklar:2",
            "schweizer-sklar:-1",
            "aczel-alsina:2",
        ]
        .iter()
        .map(|name| Accumulator::new(TConorm::new(name.parse::<Family>().unwrap()).unwrap()))
        .collect()
    }

    /// A deterministic sequence of memberships in `[0, 1]`, with exact 0 and 1 among them.
    fn memberships(n: usize) -> Vec<f32> {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        (0..n)
            .map(|i| {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                match i % 17 {
                    0 => 0.0,
                    1 => 1.0,
                    _ => ((state >> 40) as f32 / (1u64 << 24) as f32).powi(2),
                }
            })
            .collect()
    }

    #[test]
    fn accumulation_is_exactly_order_independent() {
        for acc in accumulators() {
            let evidence = memberships(200);
            let forward = evidence.iter().fold(0, |l, e| acc.accumulate(l, *e));
            let backward = evidence.iter().rev().fold(0, |l, e| acc.accumulate(l, *e));
            // Two partial accumulations, then combined: a merge.
            let (a, b) = evidence.split_at(77);
            let left = a.iter().fold(0, |l, e| acc.accumulate(l, *e));
            let right = b.iter().fold(0, |l, e| acc.accumulate(l, *e));
            assert_eq!(forward, backward, "{:?}", acc.operator());
            assert_eq!(acc.combine(left, right), forward, "{:?}", acc.operator());
            assert_eq!(acc.combine(right, left), forward, "{:?}", acc.operator());
        }
    }

    #[test]
    fn levels_read_back_close_to_the_memberships_and_keep_the_ends() {
        for acc in accumulators() {
            assert_eq!(acc.level(0.0), 0);
            assert_eq!(acc.membership(0), 0.0);
            assert_eq!(acc.membership(acc.level(1.0)), acc.max_membership());
            let mut previous = 0.0;
            for mu in (1..1000).map(|i| i as f32 / 1000.0) {
                let back = acc.membership(acc.level(mu));
                // Monotone, and within the fixed point's error where the operator can hold mu.
                assert!(back >= previous, "{:?} at {mu}", acc.operator());
                previous = back;
                if mu <= acc.max_membership() * 0.999 {
                    assert!(
                        (back - mu).abs() < 1e-4,
                        "{:?}: {mu} reads {back}",
                        acc.operator()
                    );
                }
            }
        }
        // The default operator holds every membership up to 1, and 1 itself.
        let product = Accumulator::new(TConorm::default());
        assert_eq!(product.max_membership(), 1.0);
        assert_eq!(product.membership(product.level(1.0)), 1.0);
    }

    #[test]
    fn accumulated_levels_match_an_f64_reference() {
        // Many small observations, as a voxel seen in many frames gets them.
        for acc in accumulators().into_iter().filter(|a| a.step().is_some()) {
            let evidence: Vec<f32> = memberships(400).iter().map(|m| m * 0.05).collect();
            let level = evidence.iter().fold(0, |l, e| acc.accumulate(l, *e));
            let g: f64 = evidence
                .iter()
                .map(|e| acc.operator().generator(*e).unwrap())
                .sum();
            let reference = acc.operator().generator_inverse(g).unwrap();
            let error = (acc.membership(level) - reference).abs();
            assert!(error < 1e-4, "{:?}: {error}", acc.operator());
        }
    }

    #[test]
    fn the_largest_memberships_are_as_documented() {
        let max = |name: &str| {
            Accumulator::new(TConorm::new(name.parse::<Family>().unwrap()).unwrap())
                .max_membership()
        };
        for name in [
            "product",
            "einstein",
            "frank:3",
            "hamacher:0.5",
            "aczel-alsina:2",
        ] {
            assert_eq!(max(name), 1.0, "{name}");
        }
        for (name, value) in [
            ("lukasiewicz", 1.0),
            ("yager:2", 1.0),
            ("hamacher:0", 0.99976),
            ("schweizer-sklar:-1", 0.99976),
            ("aczel-alsina:3", 0.999985),
            ("dombi:2", 0.985),
            ("dombi:10", 0.70),
        ] {
            let (got, want) = (1.0 - max(name), 1.0 - value);
            assert!(
                (got - want).abs() <= 0.05 * want + 1e-6,
                "{name}: {}",
                max(name)
            );
        }
    }

    #[test]
    fn many_levels_read_as_one_at_a_time() {
        for acc in accumulators() {
            let levels: Vec<Levels> = memberships(300)
                .chunks(2)
                .flat_map(|p| {
                    let l = acc.levels(Memberships {
                        occupied: p[0],
                        free: p[1],
                    });
                    [l, l, Levels::default(), l]
                })
                .collect();
            let mut out = vec![Memberships::default(); levels.len()];
            acc.memberships_into(&levels, &mut out);
            for (l, m) in levels.iter().zip(&out) {
                assert_eq!(*m, acc.memberships(*l), "{:?}", acc.operator());
            }
        }
    }

    #[test]
    fn bad_levels_read_as_memberships_in_range() {
        for acc in accumulators() {
            for mu in memberships(50) {
                assert!(acc.is_valid(acc.level(mu)), "{:?}", acc.operator());
            }
            // Negative zero, NaN and 2 as bits; past the cap in generator space.
            let bad = match acc.step() {
                Some(_) => acc.level(1.0) < u32::MAX && !acc.is_valid(acc.level(1.0) + 1),
                None => [(-0.5f32).to_bits(), f32::NAN.to_bits(), 2.0f32.to_bits()]
                    .iter()
                    .all(|l| !acc.is_valid(*l)),
            };
            assert!(bad || acc.level(1.0) == u32::MAX, "{:?}", acc.operator());
            for level in [1, 12_345, u32::MAX / 2, u32::MAX - 1, u32::MAX] {
                let mu = acc.membership(level);
                assert!(
                    (0.0..=1.0).contains(&mu),
                    "{:?}: {level} reads {mu}",
                    acc.operator()
                );
            }
        }
    }
}
