//! Colours shared by every figure, the PLY export and the viewer page: one table of class
//! colours, and the viridis colour map for measures (perceptually uniform, readable in grey and
//! by most colour-blind readers).
//!
//! | class | colour | RGB |
//! |---|---|---|
//! | occupied | near black | 40, 40, 40 |
//! | free | light green | 150, 210, 150 |
//! | ambiguous | orange | 235, 140, 30 |
//! | unknown | light grey | 215, 215, 215 |
//!
//! Figures draw on a white background, so unknown space (light grey) is never mistaken for the
//! page.
//!
//! The class colours ([`class_color`]) are defined in the core, beside the classes, because the
//! PLY export (`fuzzyvox-io`) writes them too; they are re-exported here.

pub use fuzzyvox_core::class::class_color;
use fuzzyvox_core::measures::VoxelClass;

/// Unknown space: never observed, or observed without a class.
pub const UNKNOWN: [u8; 3] = class_color(VoxelClass::Unknown);

/// The figures' background, outside the mapped area.
pub const BACKGROUND: [u8; 3] = [255, 255, 255];

/// Pixels without a value in depth, disparity and confidence images.
pub const NO_VALUE: [u8; 3] = [0, 0, 0];

/// Flights that stay clear of the true scene (and trajectories in figures).
pub const PATH_OK: [u8; 3] = [20, 60, 200];

/// Flights that meet the true scene.
pub const PATH_COLLIDES: [u8; 3] = [220, 30, 30];

/// The camera's trajectory, in the viewer page.
pub const PATH_TRAJECTORY: [u8; 3] = [150, 60, 190];

/// Paths of no known kind, in the viewer page.
pub const PATH_OTHER: [u8; 3] = [90, 90, 90];

/// Viridis sampled at nine evenly spaced stops; [`viridis`] interpolates between them. The
/// viewer page uses the same stops.
pub const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// The viridis colour of `t` in `[0, 1]` (clamped; NaN gives the lowest colour).
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let s = t * (VIRIDIS.len() - 1) as f64;
    let i = (s.floor() as usize).min(VIRIDIS.len() - 2);
    let f = s - i as f64;
    let (a, b) = match VIRIDIS.get(i..i + 2) {
        Some([a, b]) => (*a, *b),
        _ => (VIRIDIS[0], VIRIDIS[0]),
    };
    let mut out = a;
    for ((o, a), b) in out.iter_mut().zip(a).zip(b) {
        *o = (f64::from(a) + (f64::from(b) - f64::from(a)) * f).round() as u8;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_runs_from_purple_to_yellow_and_clamps() {
        assert_eq!(viridis(0.0), VIRIDIS[0]);
        assert_eq!(viridis(1.0), VIRIDIS[8]);
        assert_eq!(viridis(-3.0), VIRIDIS[0]);
        assert_eq!(viridis(7.0), VIRIDIS[8]);
        assert_eq!(viridis(f64::NAN), VIRIDIS[0]);
        assert_eq!(viridis(0.5), VIRIDIS[4]);
        // Lightness grows along the map.
        let luma =
            |c: [u8; 3]| 0.3 * f64::from(c[0]) + 0.59 * f64::from(c[1]) + 0.11 * f64::from(c[2]);
        for i in 1..=20 {
            assert!(luma(viridis(f64::from(i) / 20.0)) > luma(viridis(f64::from(i - 1) / 20.0)));
        }
    }

    #[test]
    fn classes_have_distinct_colours_and_unknown_is_not_the_background() {
        let colours: Vec<_> = VoxelClass::ALL.iter().map(|c| class_color(*c)).collect();
        for (i, a) in colours.iter().enumerate() {
            for b in &colours[i + 1..] {
                assert_ne!(a, b);
            }
            assert_ne!(*a, BACKGROUND);
        }
    }
}
