use super::block::Block;
use super::grid::BlockGrid;
use super::key::{BlockKey, VoxelKey};

/// Reads cells through a cache of the last block visited, so that runs of neighbouring reads
/// (a ray walk, a kernel) skip the hash lookup.
pub struct Accessor<'a, C> {
    grid: &'a BlockGrid<C>,
    last: Option<(BlockKey, Option<&'a Block<C>>)>,
}

impl<'a, C: Copy + Default> Accessor<'a, C> {
    /// An accessor over `grid`.
    pub fn new(grid: &'a BlockGrid<C>) -> Self {
        Self { grid, last: None }
    }

    /// The cell at `key`, if its block is allocated.
    #[inline]
    pub fn get(&mut self, key: VoxelKey) -> Option<&'a C> {
        let block_key = key.block();
        let block = match self.last {
            Some((cached, block)) if cached == block_key => block,
            _ => {
                let block = self.grid.block(block_key);
                self.last = Some((block_key, block));
                block
            }
        };
        block.map(|b| &b.cells[key.cell_index()])
    }
}

/// Writes cells through a cache of the last block visited, allocating blocks on demand.
///
/// The accessor is one write to the grid: it advances the grid's version when it is made and
/// records each block it writes when it enters it, so a write inside the cached block costs
/// no more than the store.
pub struct AccessorMut<'a, C> {
    grid: &'a mut BlockGrid<C>,
    last: Option<(BlockKey, usize)>,
}

impl<'a, C: Copy + Default> AccessorMut<'a, C> {
    /// A writing accessor over `grid`.
    pub fn new(grid: &'a mut BlockGrid<C>) -> Self {
        grid.begin_write();
        Self { grid, last: None }
    }

    /// The cell at `key`, allocating its block when needed.
    #[inline]
    pub fn get_or_insert(&mut self, key: VoxelKey) -> &mut C {
        self.cell_of_block(key.block(), key.cell_index())
    }

    /// Cell `cell` (an index as [`VoxelKey::cell_index`] gives it) of block `block`, allocating
    /// the block when needed: for a writer that already knows the block, such as a ray walk
    /// reporting its voxels block by block.
    #[inline]
    pub fn cell_of_block(&mut self, block: BlockKey, cell: usize) -> &mut C {
        let position = match self.last {
            Some((cached, position)) if cached == block => position,
            _ => self.enter(block),
        };
        self.grid.cell_at_mut_unrecorded(position, cell)
    }

    /// Makes `block` the accessor's current block, allocating it when needed, and returns its
    /// storage position for [`AccessorMut::cell_at`].
    #[inline]
    pub fn enter(&mut self, block: BlockKey) -> usize {
        let position = self.grid.ensure_block(block);
        self.grid.mark(position);
        self.last = Some((block, position));
        position
    }

    /// Cell `cell` of the block at storage position `position`, which [`AccessorMut::enter`]
    /// returned. Panics for a position no block has.
    #[inline]
    pub fn cell_at(&mut self, position: usize, cell: usize) -> &mut C {
        self.grid.cell_at_mut_unrecorded(position, cell)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accessors_agree_with_the_grid() {
        let mut grid = BlockGrid::<u32>::new();
        {
            let mut acc = AccessorMut::new(&mut grid);
            for i in -20..20 {
                *acc.get_or_insert(VoxelKey::new(i, i / 2, -i)) += 1 + i as u32 % 3;
            }
        }
        let mut read = Accessor::new(&grid);
        for i in -20..20 {
            let key = VoxelKey::new(i, i / 2, -i);
            assert_eq!(read.get(key), grid.cell(key));
            assert_eq!(*read.get(key).unwrap(), 1 + i as u32 % 3);
        }
        assert_eq!(read.get(VoxelKey::new(500, 0, 0)), None);
    }
}
