//! The simplified street graph of Boeing's measures: coincident nodes merged, and every
//! chain of degree-2 nodes merged into one edge that keeps its polyline length.
//!
//! A node stays a node of the simplified graph when its degree is not 2, or when its
//! two edges lead to the same neighbour (OSMnx's "endpoint" rule). A ring made only of
//! degree-2 nodes becomes a self-loop at its lowest-numbered node.
//!
//! # References
//! G. Boeing, *OSMnx: New methods for acquiring, constructing, analyzing, and
//! visualizing complex street networks*, CEUS 65 (2017), §"topological simplification".

use polis_geom::DVec2;

use crate::input::{StreetClass, StreetGraph};

/// An edge of the simplified graph: a street between two intersections or dead ends.
#[derive(Debug, Clone, PartialEq)]
pub struct SimpleEdge {
    /// First end (an input node index).
    pub a: usize,
    /// Second end (`== a` for a self-loop).
    pub b: usize,
    /// Length along the polyline, metres.
    pub length_m: f64,
    /// Straight-line distance between the ends, metres.
    pub chord_m: f64,
    /// The input nodes along the street, `a` first and `b` last.
    pub path: Vec<usize>,
    /// The input edges along the street, in path order.
    pub edges: Vec<usize>,
    /// [`StreetClass::Highway`] when at least half the length is highway.
    pub class: StreetClass,
}

impl SimpleEdge {
    /// Whether both ends are the same node.
    pub fn is_loop(&self) -> bool {
        self.a == self.b
    }
}

/// The simplified graph.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SimpleGraph {
    /// For every input node, the node it was merged into (itself unless a zero-length
    /// edge joined it to a lower-numbered node at the same position).
    pub merged_into: Vec<usize>,
    /// Degree of every input node in the simplified graph (self-loops count twice);
    /// 0 for nodes that are not nodes of it (chain interiors, merged and isolated nodes).
    pub degree: Vec<usize>,
    /// The nodes of the simplified graph (input indices, ascending).
    pub nodes: Vec<usize>,
    /// The streets.
    pub edges: Vec<SimpleEdge>,
    /// Nodes without any edge of positive length.
    pub isolated_nodes: usize,
    /// Input edges of zero length (contracted).
    pub zero_length_edges: usize,
}

/// Simplifies `g` (assumed valid: [`StreetGraph::validate`]; out-of-range edges are
/// ignored).
pub fn simplify(g: &StreetGraph) -> SimpleGraph {
    let n = g.nodes.len();
    let in_range = |e: &crate::input::StreetEdge| e.a < n && e.b < n;
    // 1. Contract zero-length edges (union–find, the lower index represents).
    let mut parent: Vec<usize> = (0..n).collect();
    let mut zero_length_edges = 0;
    for e in g.edges.iter().filter(|e| in_range(e)) {
        if g.nodes[e.a] == g.nodes[e.b] {
            zero_length_edges += 1;
            let (ra, rb) = (find(&mut parent, e.a), find(&mut parent, e.b));
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            parent[hi] = lo;
        }
    }
    let merged_into: Vec<usize> = (0..n).map(|i| find(&mut parent, i)).collect();
    // 2. Adjacency of the contracted graph, in edge order (deterministic).
    let mut adj: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
    let mut ends: Vec<(usize, usize)> = vec![(usize::MAX, usize::MAX); g.edges.len()];
    for (i, e) in g.edges.iter().enumerate() {
        if !in_range(e) {
            continue;
        }
        let (a, b) = (merged_into[e.a], merged_into[e.b]);
        if a == b {
            continue;
        }
        ends[i] = (a, b);
        adj[a].push((i, b));
        adj[b].push((i, a));
    }
    let interior = |v: usize| adj[v].len() == 2 && adj[v][0].1 != adj[v][1].1;
    let mut visited = vec![false; g.edges.len()];
    let mut edges = Vec::new();
    let mut degree = vec![0; n];
    let mut nodes = Vec::new();
    let mut isolated_nodes = 0;
    for v in 0..n {
        if merged_into[v] != v {
            continue;
        }
        if adj[v].is_empty() {
            isolated_nodes += 1;
            continue;
        }
        if interior(v) {
            continue;
        }
        nodes.push(v);
        degree[v] = adj[v].len();
        for k in 0..adj[v].len() {
            let (e, _) = adj[v][k];
            if !visited[e] {
                edges.push(walk(g, &adj, &ends, &interior, &mut visited, v, e));
            }
        }
    }
    // 3. Rings of degree-2 nodes: a self-loop at the lowest node of each.
    for e in 0..g.edges.len() {
        if visited[e] || ends[e].0 == usize::MAX {
            continue;
        }
        let ring = walk(g, &adj, &ends, &interior, &mut visited, ends[e].0, e);
        let anchor = ring.path.iter().copied().min().unwrap_or(ring.a);
        let ring = reanchor(g, ring, anchor);
        degree[anchor] = 2;
        nodes.push(anchor);
        edges.push(ring);
    }
    nodes.sort_unstable();
    SimpleGraph {
        merged_into,
        degree,
        nodes,
        edges,
        isolated_nodes,
        zero_length_edges,
    }
}

fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Follows the chain that leaves `start` along input edge `first` until a node that is
/// not interior (or `start` again, for a ring).
fn walk(
    g: &StreetGraph,
    adj: &[Vec<(usize, usize)>],
    ends: &[(usize, usize)],
    interior: &dyn Fn(usize) -> bool,
    visited: &mut [bool],
    start: usize,
    first: usize,
) -> SimpleEdge {
    let mut path = vec![start];
    let mut chain = Vec::new();
    let mut highway_len = 0.0;
    let mut length = 0.0;
    let (mut cur, mut e) = (start, first);
    loop {
        visited[e] = true;
        chain.push(e);
        let (a, b) = ends[e];
        let next = if a == cur { b } else { a };
        let seg = g.nodes[cur].distance(g.nodes[next]);
        length += seg;
        if g.edges[e].class == StreetClass::Highway {
            highway_len += seg;
        }
        path.push(next);
        cur = next;
        if cur == start || !interior(cur) {
            break;
        }
        // The interior node's other edge.
        let [(e0, _), (e1, _)] = [adj[cur][0], adj[cur][1]];
        e = if e0 == e { e1 } else { e0 };
        if visited[e] {
            break;
        }
    }
    finish(g, path, chain, length, highway_len)
}

fn finish(
    g: &StreetGraph,
    path: Vec<usize>,
    edges: Vec<usize>,
    length_m: f64,
    highway_len: f64,
) -> SimpleEdge {
    let (a, b) = (path[0], path[path.len() - 1]);
    SimpleEdge {
        a,
        b,
        length_m,
        chord_m: if a == b {
            0.0
        } else {
            g.nodes[a].distance(g.nodes[b])
        },
        path,
        edges,
        class: if highway_len * 2.0 >= length_m && length_m > 0.0 {
            StreetClass::Highway
        } else {
            StreetClass::Street
        },
    }
}

/// The same ring started at `anchor` (a node on it).
fn reanchor(g: &StreetGraph, ring: SimpleEdge, anchor: usize) -> SimpleEdge {
    let Some(k) = ring.path.iter().position(|&v| v == anchor) else {
        return ring;
    };
    // path is closed (first == last): rotate the open part.
    let open = &ring.path[..ring.path.len() - 1];
    let mut path: Vec<usize> = open[k..].iter().chain(&open[..k]).copied().collect();
    path.push(anchor);
    let edges: Vec<usize> = ring.edges[k..]
        .iter()
        .chain(&ring.edges[..k])
        .copied()
        .collect();
    let highway: f64 = edges
        .iter()
        .zip(path.windows(2))
        .filter(|(e, _)| g.edges[**e].class == StreetClass::Highway)
        .map(|(_, w)| g.nodes[w[0]].distance(g.nodes[w[1]]))
        .sum();
    finish(g, path, edges, ring.length_m, highway)
}

/// The polyline of a simplified edge.
pub fn polyline(g: &StreetGraph, e: &SimpleEdge) -> Vec<DVec2> {
    e.path.iter().map(|&v| g.nodes[v]).collect()
}
