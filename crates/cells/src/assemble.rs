//! Turns the raw sweep results into the public [`CellDecomposition`]: rings with ids and
//! polygons, filament chains, the containment of whole components (the one geometric
//! step), and self-contained cells.

use polis_geom::{EdgeId, NodeId, Polygon};

use crate::eberly::{Owner, Packed, Span, Sweep};
use crate::output::{
    Cell, CellDecomposition, CellId, ExtractionReport, Filament, FilamentKind, IsolatedNode, Ring,
};
use crate::sweep_line::SweepLine;
use crate::topology::{NONE, Topology};

fn ring(topo: &Topology, sweep: &Sweep, span: Span) -> Ring {
    let hs = &sweep.ring_buf[span.start as usize..(span.start + span.len) as usize];
    let mut nodes = Vec::with_capacity(hs.len());
    let mut edges = Vec::with_capacity(hs.len());
    let mut points = Vec::with_capacity(hs.len());
    for &h in hs {
        let o = topo.origin[h as usize];
        nodes.push(NodeId::from_raw(topo.node[o as usize]));
        edges.push(EdgeId::from_raw(topo.edge[h as usize]));
        points.push(topo.p(o));
    }
    Ring {
        nodes,
        edges,
        polygon: Polygon::new(points),
    }
}

/// For every connected component, the innermost cycle of another component containing it.
///
/// The face containing a component is the face just above the edge directly below its
/// leftmost node (from the line sweep): a cell, or the outside of an earlier component,
/// whose container is then the answer (components are numbered left to right, so that
/// one is resolved already).
fn component_containers(topo: &Topology, sweep: &Sweep, line: &SweepLine) -> Vec<Option<u32>> {
    let mut out: Vec<Option<u32>> = vec![None; sweep.components.len()];
    for k in 0..out.len() {
        let v = sweep.components[k] as usize;
        let Some(&h) = line.below.get(v) else {
            continue;
        };
        if h == NONE || h as usize >= topo.slots() {
            continue;
        }
        out[k] = match sweep.face[h as usize].get() {
            Owner::Cell(c) => Some(c),
            Owner::Outside(j) if (j as usize) < k => out[j as usize],
            _ => None,
        };
    }
    out
}

/// Maximal chains of filament edges through degree-2 nodes.
fn filament_chains(
    topo: &Topology,
    sweep: &Sweep,
    resolve: &dyn Fn(Owner) -> Option<u32>,
) -> Vec<Filament> {
    let key = |k: u32| k.min(topo.twin[k as usize]) as usize;
    let is_fil =
        |k: u32| sweep.cycle_uses[key(k)] == 0 && sweep.filament_owner[key(k)] != Packed::UNSET;
    let mut used = vec![false; topo.slots()];
    let mut out = Vec::new();
    let mut chain = |start: u32, used: &mut Vec<bool>| {
        let mut nodes = vec![topo.origin[start as usize]];
        let mut edges = Vec::new();
        let mut h = start;
        loop {
            used[key(h)] = true;
            edges.push(topo.edge[h as usize]);
            let w = topo.target[h as usize];
            nodes.push(w);
            if topo.deg0[w as usize] != 2 || w == nodes[0] {
                break;
            }
            let s = topo.adj_start[w as usize];
            let back = topo.twin[h as usize];
            let next = if s == back { s + 1 } else { s };
            if !is_fil(next) || used[key(next)] {
                break;
            }
            h = next;
        }
        let (d0, d1) = (
            topo.deg0[nodes[0] as usize],
            topo.deg0[nodes[nodes.len() - 1] as usize],
        );
        let kind = match (d0 == 1, d1 == 1) {
            (true, true) => FilamentKind::Free,
            (false, false) => FilamentKind::Connector,
            _ => FilamentKind::DeadEnd,
        };
        if d0 == 1 && d1 != 1 {
            nodes.reverse();
            edges.reverse();
        }
        let owner = sweep.filament_owner[key(start)].get();
        out.push(Filament {
            points: nodes.iter().map(|&r| topo.p(r)).collect(),
            nodes: nodes
                .into_iter()
                .map(|r| NodeId::from_raw(topo.node[r as usize]))
                .collect(),
            edges: edges.into_iter().map(EdgeId::from_raw).collect(),
            kind,
            cell: resolve(owner).map(CellId),
        });
    };
    // Chains start at nodes of degree != 2, in sweep order; what is left are closed
    // chains of degree-2 nodes, which cannot be filaments but are handled anyway.
    for pass in 0..2 {
        for r in 0..topo.len() {
            if pass == 0 && topo.deg0[r] == 2 {
                continue;
            }
            for k in topo.adj_start[r]..topo.adj_start[r + 1] {
                if is_fil(k) && !used[key(k)] {
                    chain(k, &mut used);
                }
            }
        }
    }
    out
}

/// Builds the decomposition from the sweep's raw results.
pub(crate) fn assemble(
    topo: &Topology,
    sweep: &Sweep,
    line: &SweepLine,
    report: ExtractionReport,
) -> CellDecomposition {
    let containers = component_containers(topo, sweep, line);
    let resolve = |o: Owner| -> Option<u32> {
        match o {
            Owner::Unset => None,
            Owner::Cell(c) => Some(c),
            Owner::Outside(k) => containers.get(k as usize).copied().flatten(),
        }
    };

    // The cells are built in place (no per-cell side tables: at city sizes those cost
    // as much memory traffic as the cells themselves).
    let n = sweep.cycles.len();
    let mut cells: Vec<Cell> = Vec::with_capacity(n);
    let mut roots = Vec::new();
    for (i, c) in sweep.cycles.iter().enumerate() {
        // A parent must precede its child; anything else would be a bug: cut the link.
        let parent = resolve(c.parent).filter(|&p| (p as usize) < i);
        let depth = match parent {
            Some(p) => {
                let pc = &mut cells[p as usize];
                pc.children.push(CellId(i as u32));
                pc.depth + 1
            }
            None => {
                roots.push(CellId(i as u32));
                0
            }
        };
        cells.push(Cell {
            id: CellId(i as u32),
            boundary: ring(topo, sweep, c.span),
            parent: parent.map(CellId),
            children: Vec::new(),
            depth,
            holes: Vec::new(),
            filaments: Vec::new(),
            isolated_nodes: Vec::new(),
        });
    }

    let mut outlines = Vec::new();
    for l in &sweep.loops {
        let r = ring(topo, sweep, l.span);
        match resolve(l.owner).and_then(|c| cells.get_mut(c as usize)) {
            Some(cell) => cell.holes.push(r),
            None => outlines.push(r),
        }
    }
    let mut outer_filaments = Vec::new();
    for f in filament_chains(topo, sweep, &resolve) {
        match f.cell.and_then(|c| cells.get_mut(c.index())) {
            Some(cell) => cell.filaments.push(f),
            None => outer_filaments.push(f),
        }
    }
    let mut outer_isolated = Vec::new();
    for &(v, k) in &sweep.isolated {
        let cell = resolve(Owner::Outside(k));
        let node = IsolatedNode {
            node: NodeId::from_raw(topo.node[v as usize]),
            point: topo.p(v),
            cell: cell.map(CellId),
        };
        match cell.and_then(|c| cells.get_mut(c as usize)) {
            Some(cell) => cell.isolated_nodes.push(node),
            None => outer_isolated.push(node),
        }
    }

    let mut report = report;
    report.components = sweep.components.len();
    report.cycles = n;
    let slots = topo.slots() as u32;
    report.cycle_edges = (0..slots)
        .filter(|&k| k < topo.twin[k as usize] && sweep.cycle_uses[k as usize] > 0)
        .count();
    report.filament_edges = topo.slots() / 2 - report.cycle_edges;

    CellDecomposition {
        cells,
        roots,
        outer_filaments,
        outer_isolated_nodes: outer_isolated,
        outlines,
        report,
    }
}
