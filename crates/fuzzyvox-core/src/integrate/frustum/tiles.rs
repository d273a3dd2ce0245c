//! Tile reach: the largest reach of the pixels of each square tile of the image, which bounds
//! how deep any voxel projecting into the tile can receive evidence.

use super::pixel::PixelEvidence;
use crate::integrate::footprint::FootprintFill;

/// Side of the square pixel tiles whose largest far depth culls blocks.
const TILE: u32 = 8;

/// The largest reach (far depth + δ, or max range) over square pixel tiles.
pub(super) struct TileReach {
    pub(super) columns: u32,
    pub(super) rows: u32,
    pub(super) reach: Vec<f32>,
    pub(super) max_reach: f32,
}

impl TileReach {
    /// With `fill`, a pixel without evidence reaches as far as its footprint's fill can.
    pub(super) fn new(
        pixels: &[PixelEvidence],
        fill: Option<&FootprintFill>,
        width: u32,
        height: u32,
    ) -> Self {
        let columns = width.div_ceil(TILE);
        let rows = height.div_ceil(TILE);
        let mut reach = vec![f32::NEG_INFINITY; (columns * rows) as usize];
        for (i, p) in pixels.iter().enumerate() {
            let (x, y) = (i as u32 % width, i as u32 / width);
            let t = ((y / TILE) * columns + x / TILE) as usize;
            let r = match fill {
                Some(fill) if !p.is_valid() => fill.reach(i),
                _ => p.reach,
            };
            reach[t] = reach[t].max(r);
        }
        let max_reach = reach.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        Self {
            columns,
            rows,
            reach,
            max_reach,
        }
    }

    /// Largest reach over the pixel rectangle `[u0, u1] × [v0, v1]` (inclusive).
    pub(super) fn max_over(&self, u0: u32, u1: u32, v0: u32, v1: u32) -> f32 {
        let mut best = f32::NEG_INFINITY;
        for ty in (v0 / TILE)..=(v1 / TILE).min(self.rows - 1) {
            for tx in (u0 / TILE)..=(u1 / TILE).min(self.columns - 1) {
                best = best.max(self.reach[(ty * self.columns + tx) as usize]);
            }
        }
        best
    }
}
