use serde::{Deserialize, Serialize};

use crate::class::VoxelClass;

/// Cells along one edge of a block.
pub const BLOCK_SIDE: usize = 8;
/// Cells in one block.
pub const BLOCK_CELLS: usize = BLOCK_SIDE * BLOCK_SIDE * BLOCK_SIDE;

/// How many cells of a block fall in each [`VoxelClass`]: the coarse summary that answers
/// "is anything occupied (or unknown) here?" without visiting the cells.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ClassCounts([u16; 4]);

impl ClassCounts {
    /// Counts the classes of `cells` with `classify`.
    ///
    /// Neighbouring cells often hold equal values (never observed, or updated alike by one
    /// scan), so the class of the previous cell is reused when the value repeats.
    pub fn of<C: PartialEq>(cells: &[C], classify: impl Fn(&C) -> VoxelClass) -> Self {
        let mut counts = [0u16; 4];
        let mut last: Option<(&C, VoxelClass)> = None;
        for cell in cells {
            let class = match last {
                Some((value, class)) if value == cell => class,
                _ => {
                    let class = classify(cell);
                    last = Some((cell, class));
                    class
                }
            };
            counts[class.index()] += 1;
        }
        Self(counts)
    }

    /// Counts per class, in [`VoxelClass::index`] order (each at most [`BLOCK_CELLS`]).
    pub fn from_counts(counts: [usize; 4]) -> Self {
        Self(counts.map(|n| u16::try_from(n).unwrap_or(u16::MAX)))
    }

    /// Records that one cell changed class from `from` to `to`.
    #[inline]
    pub fn moved(&mut self, from: VoxelClass, to: VoxelClass) {
        if from != to {
            self.0[from.index()] = self.0[from.index()].saturating_sub(1);
            self.0[to.index()] += 1;
        }
    }

    /// Cells of class `class`.
    #[inline]
    pub fn get(&self, class: VoxelClass) -> usize {
        usize::from(self.0[class.index()])
    }
}

/// A dense 8×8×8 block of cells with its class counts.
///
/// Cell `(x, y, z)` (each 0..8) sits at index `x + 8 y + 64 z`.
#[derive(Clone, Debug, PartialEq)]
pub struct Block<C> {
    /// The cells, x fastest.
    pub cells: [C; BLOCK_CELLS],
    /// Class counts of `cells`; kept current by the map that owns the block.
    pub summary: ClassCounts,
}

impl<C: Copy + Default> Default for Block<C> {
    /// A block of default cells, all counted as unknown (the class of a default cell in every
    /// map).
    fn default() -> Self {
        let mut summary = ClassCounts::default();
        summary.0[VoxelClass::Unknown.index()] = BLOCK_CELLS as u16;
        Self {
            cells: [C::default(); BLOCK_CELLS],
            summary,
        }
    }
}

impl<C: PartialEq> Block<C> {
    /// Recomputes the class counts after the cells changed.
    pub fn refresh_summary(&mut self, classify: impl Fn(&C) -> VoxelClass) {
        self.summary = ClassCounts::of(&self.cells, classify);
    }
}
