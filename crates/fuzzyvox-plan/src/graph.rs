use std::collections::HashSet;

use petgraph::visit::{
    Data, EdgeRef, GraphBase, GraphRef, IntoEdgeReferences, IntoEdges, IntoNeighbors, NodeCount,
    NodeIndexable, Visitable,
};

use fuzzyvox_core::storage::VoxelKey;

use crate::cost_field::CostField;

/// The 26 neighbour offsets with their lengths in voxels.
pub(crate) const NEIGHBOURS: [([i32; 3], f32); 26] = neighbour_table();

const fn neighbour_table() -> [([i32; 3], f32); 26] {
    let mut table = [([0; 3], 0.0); 26];
    let mut n = 0;
    let mut z = -1;
    while z <= 1 {
        let mut y = -1;
        while y <= 1 {
            let mut x = -1;
            while x <= 1 {
                if x != 0 || y != 0 || z != 0 {
                    let axes = (x != 0) as i32 + (y != 0) as i32 + (z != 0) as i32;
                    let length = match axes {
                        1 => 1.0,
                        2 => std::f32::consts::SQRT_2,
                        _ => 1.732_050_8,
                    };
                    table[n] = ([x, y, z], length);
                    n += 1;
                }
                x += 1;
            }
            y += 1;
        }
        z += 1;
    }
    table
}

/// The 26-connected voxel graph of a [`CostField`], without building it: nodes are the dense
/// indices of the field's region, edges join traversable voxels to their traversable
/// neighbours, and an edge's weight is its step cost.
///
/// It implements petgraph's visit traits, so petgraph's algorithms run on it directly:
///
/// ```
/// use fuzzyvox_plan::{CostField, PlannerConfig, PlanningRegion, VoxelGraph};
/// use fuzzyvox_core::{FuzzyConfig, FuzzyMap, PointCloud, VoxelKey, VoxelMap, VoxelMapMut};
/// use nalgebra::Point3;
///
/// // A wall 3 m ahead, scanned twice: the space before it is free.
/// let mut map = FuzzyMap::new(FuzzyConfig::new(0.1)?)?;
/// let wall: Vec<_> = (0..41 * 21)
///     .map(|i| Point3::new(3.0, -1.0 + 0.05 * f64::from(i % 41), 0.05 * f64::from(i / 41)))
///     .collect();
/// for _ in 0..2 {
///     let scan = PointCloud::new(Point3::new(0.0, 0.0, 0.5), wall.clone())?;
///     map.integrate_cloud(&scan, &Default::default())?;
/// }
/// let region = PlanningRegion::new(VoxelKey::new(5, -4, 1), VoxelKey::new(25, 4, 9))?;
/// let config = PlannerConfig { vehicle_radius: 0.0, ..PlannerConfig::default() };
/// let field = CostField::build(&map, region, config)?;
/// let graph = VoxelGraph::new(&field);
/// let start = graph.node(VoxelKey::new(10, 0, 5)).unwrap();
/// let goal = graph.node(VoxelKey::new(22, 0, 5)).unwrap();
/// let found = petgraph::algo::astar(
///     &graph,
///     start,
///     |n| n == goal,
///     |e| *petgraph::visit::EdgeRef::weight(&e),
///     |_| 0.0,
/// );
/// assert!(found.is_some());
/// # Ok::<(), fuzzyvox_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct VoxelGraph<'a> {
    field: &'a CostField,
}

/// One edge of a [`VoxelGraph`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoxelEdge {
    source: u32,
    target: u32,
    direction: u8,
    cost: f32,
}

impl EdgeRef for VoxelEdge {
    type NodeId = u32;
    type EdgeId = (u32, u8);
    type Weight = f32;

    fn source(&self) -> u32 {
        self.source
    }

    fn target(&self) -> u32 {
        self.target
    }

    fn weight(&self) -> &f32 {
        &self.cost
    }

    fn id(&self) -> (u32, u8) {
        (self.source, self.direction)
    }
}

impl<'a> VoxelGraph<'a> {
    /// The graph of `field`.
    pub fn new(field: &'a CostField) -> Self {
        Self { field }
    }

    /// The field behind the graph.
    pub fn field(&self) -> &'a CostField {
        self.field
    }

    /// The node of a voxel, if it lies in the region.
    pub fn node(&self, key: VoxelKey) -> Option<u32> {
        self.field.region().index_of(key).map(|i| i as u32)
    }

    /// The voxel of a node.
    pub fn key(&self, node: u32) -> VoxelKey {
        self.field.region().key_at(node as usize)
    }

    /// The edges leaving `node` (none when the node is not traversable).
    pub fn edges_from(&self, node: u32) -> Edges<'a> {
        let region = self.field.region();
        let [nx, ny, _] = region.dims();
        let index = node as usize;
        Edges {
            field: self.field,
            source: node,
            coords: [
                (index % nx) as i64,
                ((index / nx) % ny) as i64,
                (index / (nx * ny)) as i64,
            ],
            direction: if self.field.is_traversable(index) {
                0
            } else {
                NEIGHBOURS.len() as u8
            },
        }
    }
}

/// Iterator over the edges leaving one node.
#[derive(Clone, Debug)]
pub struct Edges<'a> {
    field: &'a CostField,
    source: u32,
    coords: [i64; 3],
    direction: u8,
}

impl Iterator for Edges<'_> {
    type Item = VoxelEdge;

    #[inline]
    fn next(&mut self) -> Option<VoxelEdge> {
        let dims = self.field.region().dims().map(|d| d as i64);
        let size = self.field.resolution().size() as f32;
        while (self.direction as usize) < NEIGHBOURS.len() {
            let direction = self.direction;
            self.direction += 1;
            let ([dx, dy, dz], length) = NEIGHBOURS[direction as usize];
            let (x, y, z) = (
                self.coords[0] + i64::from(dx),
                self.coords[1] + i64::from(dy),
                self.coords[2] + i64::from(dz),
            );
            if x < 0 || y < 0 || z < 0 || x >= dims[0] || y >= dims[1] || z >= dims[2] {
                continue;
            }
            let target = (x + dims[0] * (y + dims[1] * z)) as usize;
            let rate = self.field.rate(target);
            if !rate.is_finite() {
                continue;
            }
            let metres = length * size;
            return Some(VoxelEdge {
                source: self.source,
                target: target as u32,
                direction,
                cost: metres * 0.5 * (self.field.rate(self.source as usize) + rate),
            });
        }
        None
    }
}

impl GraphBase for VoxelGraph<'_> {
    type NodeId = u32;
    type EdgeId = (u32, u8);
}

impl GraphRef for VoxelGraph<'_> {}

impl Data for VoxelGraph<'_> {
    type NodeWeight = ();
    type EdgeWeight = f32;
}

impl<'a> IntoNeighbors for VoxelGraph<'a> {
    type Neighbors = std::iter::Map<Edges<'a>, fn(VoxelEdge) -> u32>;

    fn neighbors(self, node: u32) -> Self::Neighbors {
        self.edges_from(node).map(|e| e.target)
    }
}

impl<'a> IntoEdges for VoxelGraph<'a> {
    type Edges = Edges<'a>;

    fn edges(self, node: u32) -> Edges<'a> {
        self.edges_from(node)
    }
}

impl<'a> IntoEdgeReferences for VoxelGraph<'a> {
    type EdgeRef = VoxelEdge;
    type EdgeReferences = Box<dyn Iterator<Item = VoxelEdge> + 'a>;

    fn edge_references(self) -> Self::EdgeReferences {
        let nodes = self.field.region().len() as u32;
        Box::new((0..nodes).flat_map(move |n| self.edges_from(n)))
    }
}

impl Visitable for VoxelGraph<'_> {
    type Map = HashSet<u32>;

    fn visit_map(&self) -> HashSet<u32> {
        HashSet::new()
    }

    fn reset_map(&self, map: &mut HashSet<u32>) {
        map.clear();
    }
}

impl NodeIndexable for VoxelGraph<'_> {
    fn node_bound(&self) -> usize {
        self.field.region().len()
    }

    fn to_index(&self, node: u32) -> usize {
        node as usize
    }

    fn from_index(&self, index: usize) -> u32 {
        index as u32
    }
}

impl NodeCount for VoxelGraph<'_> {
    fn node_count(&self) -> usize {
        self.field.region().len()
    }
}
