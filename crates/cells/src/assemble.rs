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
    let boundaries: Vec<Ring> = sweep
        .cycles
        .iter()
        .map(|c| ring(topo, sweep, c.span))
        .collect();
    let containers = component_containers(topo, sweep, line);
    let resolve = |o: Owner| -> Option<u32> {
        match o {
            Owner::Unset => None,
            Owner::Cell(c) => Some(c),
            Owner::Outside(k) => containers.get(k as usize).copied().flatten(),
        }
    };

    let n = boundaries.len();
    let mut parents: Vec<Option<u32>> = sweep.cycles.iter().map(|c| resolve(c.parent)).collect();
    // A parent must precede its child; anything else would be a bug: cut the link.
    for (i, p) in parents.iter_mut().enumerate() {
        if p.is_some_and(|p| p as usize >= i) {
            *p = None;
        }
    }
    let mut depth = vec![0u32; n];
    let mut children: Vec<Vec<CellId>> = vec![Vec::new(); n];
    let mut roots = Vec::new();
    for i in 0..n {
        match parents[i] {
            Some(p) => {
                depth[i] = depth[p as usize] + 1;
                children[p as usize].push(CellId(i as u32));
            }
            None => roots.push(CellId(i as u32)),
        }
    }

    let mut holes: Vec<Vec<Ring>> = vec![Vec::new(); n];
    let mut outlines = Vec::new();
    for l in &sweep.loops {
        let r = ring(topo, sweep, l.span);
        match resolve(l.owner) {
            Some(c) => holes[c as usize].push(r),
            None => outlines.push(r),
        }
    }
    let mut fils: Vec<Vec<Filament>> = vec![Vec::new(); n];
    let mut outer_filaments = Vec::new();
    for f in filament_chains(topo, sweep, &resolve) {
        match f.cell {
            Some(c) => fils[c.index()].push(f),
            None => outer_filaments.push(f),
        }
    }
    let mut isolated: Vec<Vec<IsolatedNode>> = vec![Vec::new(); n];
    let mut outer_isolated = Vec::new();
    for &(v, k) in &sweep.isolated {
        let cell = resolve(Owner::Outside(k));
        let node = IsolatedNode {
            node: NodeId::from_raw(topo.node[v as usize]),
            point: topo.p(v),
            cell: cell.map(CellId),
        };
        match cell {
            Some(c) => isolated[c as usize].push(node),
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

    let cells = boundaries
        .into_iter()
        .zip(holes)
        .zip(fils)
        .zip(isolated)
        .enumerate()
        .map(
            |(i, (((boundary, holes), filaments), isolated_nodes))| Cell {
                id: CellId(i as u32),
                boundary,
                parent: parents[i].map(CellId),
                children: std::mem::take(&mut children[i]),
                depth: depth[i],
                holes,
                filaments,
                isolated_nodes,
            },
        )
        .collect();
    CellDecomposition {
        cells,
        roots,
        outer_filaments,
        outer_isolated_nodes: outer_isolated,
        outlines,
        report,
    }
}
