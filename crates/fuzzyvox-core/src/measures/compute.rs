use serde::{Deserialize, Serialize};

use super::class::ClassThresholds;
use crate::class::VoxelClass;
use crate::error::Result;
use crate::ops::unit;
use crate::ops::{Family, Hedge, TNorm};

/// A voxel's two membership degrees, each in `[0, 1]` and independent of each other.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Memberships {
    /// How occupied (μO).
    pub occupied: f32,
    /// How free, "empty" (μE).
    pub free: f32,
}

/// How measures and classes are computed: the t-norm `T` (minimum by default) and the class
/// thresholds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MeasureConfig {
    /// The t-norm behind ambiguity, indeterminacy and safety.
    pub tnorm: TNorm,
    /// Thresholds for [`VoxelClass`].
    pub thresholds: ClassThresholds,
}

impl MeasureConfig {
    /// Checks the thresholds (the t-norm is valid by construction).
    pub fn validate(self) -> Result<Self> {
        self.thresholds.validate()?;
        Ok(self)
    }

    /// All measures of one voxel.
    pub fn measures(&self, m: Memberships) -> Measures {
        let (ambiguity, indeterminacy, safety) = self.core(m);
        Measures {
            occupied: m.occupied,
            free: m.free,
            ambiguity,
            indeterminacy,
            safety,
            certainty: m.occupied - m.free,
            contradiction: m.occupied + m.free - 1.0,
            class: self.classify_with_ambiguity(m, ambiguity),
        }
    }

    /// A voxel's safety and class: what a planner reads, without the other measures.
    #[inline]
    pub fn safety_and_class(&self, m: Memberships) -> (f32, VoxelClass) {
        let (ambiguity, _, safety) = self.core(m);
        (safety, self.classify_with_ambiguity(m, ambiguity))
    }

    /// Ambiguity, indeterminacy and safety.
    #[inline]
    fn core(&self, m: Memberships) -> (f32, f32, f32) {
        if self.tnorm.family() == Family::Minimum {
            // The default t-norm, without the per-call dispatch (a planner reads measures of
            // every voxel it updates): the same values, since every operand below already
            // lies in [0, 1], where `T` is `min`.
            let (o, f) = (unit(m.occupied), unit(m.free));
            let ambiguity = o.min(f);
            let indeterminacy = (1.0 - o).min(1.0 - f);
            let safety = (f * f).min((1.0 - o).min((1.0 - ambiguity).min(1.0 - indeterminacy)));
            return (ambiguity, indeterminacy, safety);
        }
        let t = |a, b| self.tnorm.apply(a, b);
        let not = |a: f32| 1.0 - a;
        let ambiguity = t(m.occupied, m.free);
        let indeterminacy = t(not(m.occupied), not(m.free));
        // "Very free, and not occupied, and not ambiguous, and not unknown".
        let safety = t(
            Hedge::Concentration.apply(m.free),
            t(not(m.occupied), t(not(ambiguity), not(indeterminacy))),
        );
        (ambiguity, indeterminacy, safety)
    }

    /// The class of one voxel (see [`ClassThresholds`] for the rule).
    #[inline]
    pub fn classify(&self, m: Memberships) -> VoxelClass {
        if m.occupied == 0.0 && m.free == 0.0 {
            return VoxelClass::Unknown;
        }
        self.classify_with_ambiguity(m, self.tnorm.apply(m.occupied, m.free))
    }

    #[inline]
    fn classify_with_ambiguity(&self, m: Memberships, ambiguity: f32) -> VoxelClass {
        let th = &self.thresholds;
        if ambiguity >= th.ambiguity {
            VoxelClass::Ambiguous
        } else if m.occupied >= th.occupied && m.occupied > m.free {
            VoxelClass::Occupied
        } else if m.free >= th.free && m.free > m.occupied {
            VoxelClass::Free
        } else {
            VoxelClass::Unknown
        }
    }
}

/// Every measure of one voxel.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Measures {
    /// Occupied membership μO.
    pub occupied: f32,
    /// Free membership μE.
    pub free: f32,
    /// `A = T(μO, μE)`: both sets claim the voxel.
    pub ambiguity: f32,
    /// `I = T(1 - μO, 1 - μE)`: neither set claims it.
    pub indeterminacy: f32,
    /// `S = T(μE², T(1 - μO, T(1 - A, 1 - I)))`: very free, not occupied, not ambiguous, not
    /// unknown.
    pub safety: f32,
    /// `μO - μE` in `[-1, 1]` (paraconsistent certainty).
    pub certainty: f32,
    /// `μO + μE - 1` in `[-1, 1]` (paraconsistent contradiction).
    pub contradiction: f32,
    /// The voxel's class.
    pub class: VoxelClass,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(occupied: f32, free: f32) -> Memberships {
        Memberships { occupied, free }
    }

    #[test]
    fn classes_follow_the_documented_rule() {
        let cfg = MeasureConfig::default();
        assert_eq!(cfg.classify(m(0.0, 0.0)), VoxelClass::Unknown);
        assert_eq!(cfg.classify(m(0.7, 0.3)), VoxelClass::Occupied);
        assert_eq!(cfg.classify(m(0.3, 0.6)), VoxelClass::Free);
        assert_eq!(cfg.classify(m(0.8, 0.6)), VoxelClass::Ambiguous);
        assert_eq!(cfg.classify(m(0.3, 0.3)), VoxelClass::Unknown);
        // Log-odds cells map through μO = p, μE = 1 - p: occupied exactly when p > 0.5.
        assert_eq!(cfg.classify(m(0.52, 0.48)), VoxelClass::Occupied);
        assert_eq!(cfg.classify(m(0.49, 0.51)), VoxelClass::Free);
    }

    #[test]
    fn safety_needs_strong_free_and_nothing_else() {
        let cfg = MeasureConfig::default();
        let safe = cfg.measures(m(0.0, 0.95));
        assert!((safe.safety - 0.9025).abs() < 1e-6, "{}", safe.safety);
        assert_eq!(safe.class, VoxelClass::Free);
        let unknown = cfg.measures(m(0.0, 0.0));
        assert_eq!(unknown.safety, 0.0);
        assert_eq!(unknown.indeterminacy, 1.0);
        let conflict = cfg.measures(m(0.9, 0.9));
        assert!(conflict.safety <= 0.1 + 1e-6);
        assert!((conflict.ambiguity - 0.9).abs() < 1e-6);
        assert!((conflict.contradiction - 0.8).abs() < 1e-6);
        assert!((cfg.measures(m(0.7, 0.2)).certainty - 0.5).abs() < 1e-6);
    }

    #[test]
    fn thresholds_are_validated() {
        let mut cfg = MeasureConfig::default();
        cfg.thresholds.free = 0.0;
        assert!(cfg.validate().is_err());
        cfg.thresholds.free = f32::NAN;
        assert!(cfg.validate().is_err());
    }
}
