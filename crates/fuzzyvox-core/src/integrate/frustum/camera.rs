//! The camera as seen from the voxel grid ([`CameraView`]), and the evidence of one block: each
//! voxel centre projected into the image and read against its pixel's evidence (or, in a
//! footprint, against the footprint's fill).

use nalgebra::{Matrix3, Point3, Vector3};

use super::pixel::PixelEvidence;
use crate::integrate::depth_image::DepthFrame;
use crate::integrate::evidence::{Evidence, EvidenceModel};
use crate::integrate::footprint::FootprintFill;
use crate::ops::TConorm;
use crate::storage::{BLOCK_CELLS, Block, BlockKey, Resolution};

/// The camera as seen from the voxel grid: everything needed to project voxel centres.
pub(super) struct CameraView {
    pub(super) camera_from_world: Matrix3<f64>,
    pub(super) camera_in_world: Vector3<f64>,
    /// Inward unit normals of the four planes through the camera centre that bound the image
    /// (`u >= -0.5`, `u <= w - 0.5`, `v >= -0.5`, `v <= h - 0.5`), in the camera frame.
    pub(super) sides: [Vector3<f64>; 4],
    pub(super) fx: f64,
    pub(super) fy: f64,
    pub(super) cx: f64,
    pub(super) cy: f64,
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) resolution: Resolution,
}

impl CameraView {
    pub(super) fn new(frame: &DepthFrame, resolution: &Resolution) -> Self {
        let pose = frame.world_from_camera();
        let k = frame.intrinsics();
        let (w, h) = (f64::from(k.width()), f64::from(k.height()));
        let sides = [
            Vector3::new(k.fx(), 0.0, k.cx() + 0.5),
            Vector3::new(-k.fx(), 0.0, w - 0.5 - k.cx()),
            Vector3::new(0.0, k.fy(), k.cy() + 0.5),
            Vector3::new(0.0, -k.fy(), h - 0.5 - k.cy()),
        ]
        .map(|n| n.normalize());
        Self {
            camera_from_world: pose.rotation.to_rotation_matrix().matrix().transpose(),
            camera_in_world: pose.translation.vector,
            sides,
            fx: k.fx(),
            fy: k.fy(),
            cx: k.cx(),
            cy: k.cy(),
            width: k.width(),
            height: k.height(),
            resolution: *resolution,
        }
    }

    pub(super) fn to_camera(&self, p: &Point3<f64>) -> Vector3<f64> {
        self.camera_from_world * (p.coords - self.camera_in_world)
    }
}

dispatched! {
    /// Evidence for one block's voxels seen by `view`, or `None` when no voxel received any.
    /// Dispatched to AVX-512 or AVX2 (`crate::dispatch`): the projection's divisions and floors
    /// then run as single instructions, with the same results.
    pub(super) fn block_evidence(
        view: &CameraView,
        key: BlockKey,
        pixels: &[PixelEvidence],
        fill: Option<&FootprintFill>,
        model: &EvidenceModel,
        operator: &TConorm,
        delta: f32,
    ) -> Option<Box<Block<Evidence>>> {
        // A voxel's footprint radius in pixels is `fx δ / z`.
        let footprint = (view.fx.max(view.fy) as f32) * delta;
        let size = view.resolution.size();
        let first = view.to_camera(&view.resolution.center(key.origin()));
        let step_x = view.camera_from_world.column(0) * size;
        let step_y = view.camera_from_world.column(1) * size;
        let step_z = view.camera_from_world.column(2) * size;
        let mut block: Option<Box<Block<Evidence>>> = None;
        for cell in 0..BLOCK_CELLS {
            let (i, j, l) = (cell % 8, (cell / 8) % 8, cell / 64);
            let p = first + step_x * i as f64 + step_y * j as f64 + step_z * l as f64;
            if p.z <= 0.0 {
                continue;
            }
            let u = (view.fx * p.x / p.z + view.cx + 0.5).floor();
            let v = (view.fy * p.y / p.z + view.cy + 0.5).floor();
            if !(u >= 0.0 && v >= 0.0 && u < f64::from(view.width) && v < f64::from(view.height)) {
                continue;
            }
            let index = v as usize * view.width as usize + u as usize;
            let z = p.z as f32;
            let pixel = &pixels[index];
            let evidence = match fill {
                Some(fill) if !pixel.is_valid() => fill
                    .lookup(index, footprint / z)
                    .filter(|&(bound, _)| z < bound)
                    .map(|(_, weight)| Evidence {
                        occupied: 0.0,
                        free: model.free(operator, weight),
                    }),
                _ => pixel.at(z, model, operator, delta),
            };
            if let Some(e) = evidence {
                block.get_or_insert_with(Box::default).cells[cell] = e;
            }
        }
        block
}
}
