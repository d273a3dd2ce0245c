//! What the vehicle knows before take-off: the true surroundings of its start.

use fuzzyvox_core::error::Result;
use fuzzyvox_core::integrate::{DepthFrame, IntegrationOptions, IntervalDepthImage};
use fuzzyvox_core::map::AnyMap;
use fuzzyvox_sim::render;
use fuzzyvox_sim::scenario::Scenario;
use fuzzyvox_sim::trajectory::look_at;
use nalgebra::{Point3, Vector3};

use crate::config::FlyConfig;

/// The prior map: what the vehicle knows of its surroundings before take-off. Six true depth
/// images from the start (four level directions, up and down), cut at the prior radius: the
/// surfaces within it and the free space in front of them, with full confidence.
pub fn integrate_prior(
    scenario: &Scenario,
    map: &mut AnyMap,
    start: &Point3<f64>,
    config: &FlyConfig,
) -> Result<()> {
    let directions = [
        Vector3::x(),
        Vector3::y(),
        -Vector3::x(),
        -Vector3::y(),
        Vector3::new(0.01, 0.0, 1.0),
        Vector3::new(0.01, 0.0, -1.0),
    ];
    let options = IntegrationOptions {
        max_range: Some(config.prior_radius),
    };
    for direction in directions {
        let pose = look_at(*start, direction);
        let k = scenario.intrinsics;
        let view = render(&scenario.scene, &k, &pose, 0, scenario.max_range * 4.0);
        // Sky: far away, so that the ray clears free space up to the prior radius.
        let far = (scenario.max_range * 4.0) as f32;
        let depth: Vec<f32> = view
            .depth
            .iter()
            .map(|z| if z.is_finite() { *z } else { far })
            .collect();
        let image =
            IntervalDepthImage::from_depth(view.width, view.height, &depth, |z| (z, z, 1.0))?;
        map.as_map_mut()
            .integrate_depth(&DepthFrame::new(k, pose, image)?, &options)?;
    }
    Ok(())
}
