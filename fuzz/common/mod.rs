//! Structured inputs shared by the integration targets: numbers that are either raw (any bit
//! pattern, NaN and infinities included) or drawn from a realistic range, so that the fuzzer
//! reaches deep code as well as the validation at its door.

#![allow(dead_code)]

use arbitrary::Arbitrary;
use fuzzyvox::{Family, TConorm};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

/// A length or coordinate in metres.
#[derive(Arbitrary, Debug, Clone, Copy)]
pub enum Metres {
    /// Any `f64`.
    Raw(f64),
    /// Centimetres: ±327 m.
    Centimetres(i16),
}

impl Metres {
    pub fn value(self) -> f64 {
        match self {
            Metres::Raw(v) => v,
            Metres::Centimetres(c) => f64::from(c) * 0.01,
        }
    }
}

/// A voxel size.
#[derive(Arbitrary, Debug, Clone, Copy)]
pub enum Resolution {
    Raw(f64),
    Table(u8),
}

impl Resolution {
    pub fn value(self) -> f64 {
        match self {
            Resolution::Raw(v) => v,
            Resolution::Table(i) => [0.02, 0.05, 0.1, 0.25, 1.0][usize::from(i) % 5],
        }
    }
}

/// An aggregation operator: a family of the catalogue, with its parameter replaced when given.
#[derive(Arbitrary, Debug, Clone, Copy)]
pub struct Operator {
    family: u8,
    parameter: Option<f64>,
}

impl Operator {
    pub fn family(self) -> Family {
        let catalogue = Family::catalogue();
        let family = catalogue[usize::from(self.family) % catalogue.len()];
        match (family, self.parameter) {
            (Family::Hamacher { .. }, Some(gamma)) => Family::Hamacher { gamma },
            (Family::Yager { .. }, Some(p)) => Family::Yager { p },
            (Family::Frank { .. }, Some(s)) => Family::Frank { s },
            (Family::Dombi { .. }, Some(lambda)) => Family::Dombi { lambda },
            (Family::SchweizerSklar { .. }, Some(p)) => Family::SchweizerSklar { p },
            (Family::AczelAlsina { .. }, Some(p)) => Family::AczelAlsina { p },
            (family, _) => family,
        }
    }

    pub fn tconorm(self) -> Option<TConorm> {
        TConorm::new(self.family()).ok()
    }
}

/// A rotation: any quaternion (unchecked, possibly not unit or not finite) or Euler angles in
/// milliradians.
#[derive(Arbitrary, Debug, Clone, Copy)]
pub enum Rotation {
    Raw([f64; 4]),
    Euler([i16; 3]),
}

impl Rotation {
    pub fn value(self) -> UnitQuaternion<f64> {
        match self {
            Rotation::Raw([w, x, y, z]) => {
                UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z))
            }
            Rotation::Euler([r, p, y]) => {
                let angle = |a: i16| f64::from(a) * 1e-3;
                UnitQuaternion::from_euler_angles(angle(r), angle(p), angle(y))
            }
        }
    }
}

/// A pose: translation and rotation.
#[derive(Arbitrary, Debug, Clone, Copy)]
pub struct Pose {
    pub translation: [Metres; 3],
    pub rotation: Rotation,
}

impl Pose {
    pub fn value(self) -> Isometry3<f64> {
        let [x, y, z] = self.translation.map(Metres::value);
        Isometry3::from_parts(Translation3::new(x, y, z), self.rotation.value())
    }
}
