//! A* itself, a pure algorithm: over any graph whose nodes are dense indices (petgraph's
//! [`IntoEdges`] with `u32` nodes and `f32` weights), with dense per-node arrays and the
//! caller's heuristic. It knows nothing of maps or fields; [`plan_in_field`](crate::plan_in_field)
//! runs it over a cost field's [`VoxelGraph`](crate::VoxelGraph).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use ordered_float::OrderedFloat;
use petgraph::visit::{EdgeRef, IntoEdges};

/// A route A* found.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Route {
    /// The nodes from start to goal, both included.
    pub(crate) nodes: Vec<usize>,
    /// The summed edge weights from start to goal.
    pub(crate) cost: f32,
    /// Nodes expanded.
    pub(crate) expanded: usize,
}

/// A* from `start` to `goal` over the `node_count` nodes of `graph`, never entering a node
/// for which `avoid` is true (the start is never tested). `heuristic` must be consistent: the
/// first time a node is expanded its cost is final. Ties in the open set are broken by node
/// index, so the result is deterministic.
///
/// Returns the route, or the number of nodes expanded when the goal cannot be reached.
pub(crate) fn astar<G, H, A>(
    graph: G,
    node_count: usize,
    start: usize,
    goal: usize,
    heuristic: H,
    avoid: &A,
) -> Result<Route, usize>
where
    G: IntoEdges<NodeId = u32, EdgeWeight = f32>,
    H: Fn(usize) -> f32,
    A: Fn(usize) -> bool + ?Sized,
{
    let n = node_count;
    let mut best = vec![f32::INFINITY; n];
    let mut parent = vec![u32::MAX; n];
    let mut closed = vec![false; n];
    let mut open = BinaryHeap::new();
    best[start] = 0.0;
    open.push(Reverse((OrderedFloat(heuristic(start)), start as u32)));
    let mut expanded = 0;
    while let Some(Reverse((_, node))) = open.pop() {
        let node_index = node as usize;
        if closed[node_index] {
            continue;
        }
        closed[node_index] = true;
        expanded += 1;
        if node_index == goal {
            break;
        }
        let g = best[node_index];
        for edge in graph.edges(node) {
            let target = edge.target() as usize;
            if closed[target] || avoid(target) {
                continue;
            }
            let candidate = g + *edge.weight();
            if candidate < best[target] {
                best[target] = candidate;
                parent[target] = node;
                let f = candidate + heuristic(target);
                open.push(Reverse((OrderedFloat(f), target as u32)));
            }
        }
    }
    if !closed[goal] {
        return Err(expanded);
    }
    let mut nodes = vec![goal];
    let mut node = goal;
    while node != start {
        node = parent[node] as usize;
        nodes.push(node);
    }
    nodes.reverse();
    Ok(Route {
        nodes,
        cost: best[goal],
        expanded,
    })
}
