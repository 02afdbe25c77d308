//! Eberly's minimal-cycle-basis sweep on the working graph.
//!
//! The vertices are visited in `(x, y)` order. At the leftmost live vertex `v0`, the
//! clockwise-most edge `v0 → v1` (seen when arriving from straight above) is taken, and
//! the walk continues by always turning counter-clockwise-most (the sharpest left turn).
//! That walk runs around the face `F` to the left of `v0 → v1`, which is bounded because
//! the wedge to the right of that edge at the leftmost vertex is the outside.
//!
//! Where Eberly's 2005 text handles revisited vertices with special cases, this
//! implementation splits the closed walk into simple loops with a stack (a vertex seen
//! again closes a loop): the loop through `v0 → v1` is the minimal cycle of `F`; every
//! other loop is either an edge walked both ways (a filament: a dead end, a tree, or a
//! connector to an island) or a clockwise loop around an island attached to the cycle at a
//! cut vertex. The cycle's half-edges are marked; then `F` counts as outside, and every
//! edge with the outside on both sides is removed — the cycle edges no other face needs
//! and the filaments (Eberly's "filaments detached"). A vertex with no edges left is done.
//!
//! The first time the sweep reaches a connected component, the outside of that component
//! is walked once the same way, which detaches the filaments and finds the islands'
//! outlines there. Every half-edge is walked once, so after the `O(n log n)` sort the sweep
//! is linear.
//!
//! Containment comes from the walks too: a face entered through the outline of an island
//! lies directly inside the face that walked that outline, and a face entered through a
//! cycle edge has the same parent as the cycle's face (same biconnected block). Only a
//! whole connected component nested in another one needs a geometric test, done later.

use crate::error::Error;
use crate::topology::{NONE, Topology};

/// Who owns a piece of a walk.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Owner {
    /// Nothing (not walked yet).
    Unset,
    /// Cell (minimal cycle) with this index.
    Cell(u32),
    /// The outside of connected component with this index; resolved geometrically.
    Outside(u32),
}

/// An [`Owner`] in four bytes (the per-half-edge tables are the sweep's largest): `Unset`
/// as `u32::MAX`, a cell as its index, an outside with the top bit set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Packed(u32);

impl Packed {
    pub(crate) const UNSET: Packed = Packed(u32::MAX);
    const OUTSIDE: u32 = 1 << 31;

    /// The owner.
    #[inline]
    pub(crate) fn get(self) -> Owner {
        match self.0 {
            u32::MAX => Owner::Unset,
            x if x & Self::OUTSIDE != 0 => Owner::Outside(x & !Self::OUTSIDE),
            x => Owner::Cell(x),
        }
    }
}

impl From<Owner> for Packed {
    #[inline]
    fn from(o: Owner) -> Packed {
        match o {
            Owner::Unset => Packed::UNSET,
            Owner::Cell(c) => Packed(c & !Packed::OUTSIDE),
            Owner::Outside(k) => Packed(k | Packed::OUTSIDE),
        }
    }
}

/// A range of `Sweep::ring_buf`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Span {
    pub(crate) start: u32,
    pub(crate) len: u32,
}

/// A minimal cycle as found by the sweep.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RawCycle {
    pub(crate) span: Span,
    pub(crate) parent: Owner,
}

/// An island outline (clockwise loop) and the face it was walked from.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RawLoop {
    pub(crate) span: Span,
    pub(crate) owner: Owner,
}

/// Buffers and raw results of the sweep.
#[derive(Debug, Default)]
pub(crate) struct Sweep {
    /// Half-edge lies on the outside (its left face was walked).
    out: Vec<bool>,
    /// By half-edge: the face to its left (the walk it was on).
    pub(crate) face: Vec<Packed>,
    /// For a walked half-edge: the parent of faces entered across it.
    tag: Vec<Packed>,
    on_stack: Vec<u32>,
    stack_v: Vec<u32>,
    stack_h: Vec<u32>,
    walk: Vec<u32>,
    /// How many cycles use each edge (indexed by the edge's smaller slot).
    pub(crate) cycle_uses: Vec<u8>,
    /// For filament edges (indexed by the smaller slot): the face they lie in.
    pub(crate) filament_owner: Vec<Packed>,
    /// Half-edges of all cycles and loops.
    pub(crate) ring_buf: Vec<u32>,
    pub(crate) cycles: Vec<RawCycle>,
    pub(crate) loops: Vec<RawLoop>,
    /// Leftmost node of every connected component, in sweep order.
    pub(crate) components: Vec<u32>,
    /// Isolated nodes with their component index.
    pub(crate) isolated: Vec<(u32, u32)>,
    /// Half-edges walked in the last run (each exactly once).
    pub(crate) walked: usize,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// Walking a bounded face that becomes cell `cell`; cycle edges get `parent`.
    Face { cell: u32, parent: Owner },
    /// Walking the outside of component `comp`.
    Outside { comp: u32 },
}

impl Sweep {
    fn reset(&mut self, topo: &Topology) {
        let hcount = topo.slots();
        let n = topo.len();
        self.out.clear();
        self.out.resize(hcount, false);
        self.tag.clear();
        self.tag.resize(hcount, Packed::UNSET);
        self.face.clear();
        self.face.resize(hcount, Packed::UNSET);
        self.on_stack.clear();
        self.on_stack.resize(n, NONE);
        self.cycle_uses.clear();
        self.cycle_uses.resize(hcount, 0);
        self.filament_owner.clear();
        self.filament_owner.resize(hcount, Packed::UNSET);
        self.ring_buf.clear();
        self.cycles.clear();
        self.loops.clear();
        self.components.clear();
        self.isolated.clear();
        self.walked = 0;
    }

    /// Runs the sweep over the whole working graph (which it consumes: every edge is
    /// removed by the end).
    pub(crate) fn run(&mut self, topo: &mut Topology) -> Result<(), Error> {
        self.reset(topo);
        let mut i = 0;
        while i < topo.len() {
            let v0 = i as u32;
            if topo.deg[v0 as usize] == 0 {
                if topo.deg0[v0 as usize] == 0 {
                    let comp = self.components.len() as u32;
                    self.components.push(v0);
                    self.isolated.push((v0, comp));
                }
                i += 1;
                continue;
            }
            let e1 = topo.clockwise_most(v0);
            let back = topo.twin[e1 as usize];
            if !self.out[back as usize] {
                // First visit of this connected component: walk its outside.
                let comp = self.components.len() as u32;
                self.components.push(v0);
                self.walk_and_split(topo, back, Mode::Outside { comp })?;
            } else if self.out[e1 as usize] {
                // Outside on both sides: cannot survive a walk, but never loop on it.
                topo.remove_edge(e1);
            } else {
                let cell = self.cycles.len() as u32;
                let parent = self.tag[back as usize].get();
                self.walk_and_split(topo, e1, Mode::Face { cell, parent })?;
                if self.cycles.len() as u32 != cell + 1 {
                    return Err(Error::Internal(format!(
                        "the walk from node {v0} closed no cycle"
                    )));
                }
            }
        }
        Ok(())
    }

    /// Walks the face left of `start` (counter-clockwise-most turns), splits the closed
    /// walk into loops, records them, marks the walk as outside and removes every edge
    /// that now has the outside on both sides.
    fn walk_and_split(&mut self, topo: &mut Topology, start: u32, mode: Mode) -> Result<(), Error> {
        self.walk.clear();
        let limit = topo.slots();
        let mut h = start;
        loop {
            self.walk.push(h);
            // Arriving at the target of h: the sharpest left turn is the edge just
            // clockwise of the way back.
            h = topo.prv[topo.twin[h as usize] as usize];
            if h == start {
                break;
            }
            if h == NONE || self.walk.len() > limit {
                return Err(Error::Internal(format!(
                    "the face walk from half-edge {start} does not close"
                )));
            }
        }

        self.walked += self.walk.len();
        let v0 = topo.origin[start as usize];
        self.stack_v.clear();
        self.stack_h.clear();
        self.stack_v.push(v0);
        self.on_stack[v0 as usize] = 0;
        let mut main_done = matches!(mode, Mode::Outside { .. });
        for k in 0..self.walk.len() {
            let h = self.walk[k];
            let w = topo.target[h as usize];
            let at = self.on_stack[w as usize];
            if at == NONE {
                self.on_stack[w as usize] = self.stack_v.len() as u32;
                self.stack_v.push(w);
                self.stack_h.push(h);
                continue;
            }
            let at = at as usize;
            let is_main = !main_done && at == 0;
            self.close_loop(topo, at, h, mode, is_main);
            main_done |= is_main;
            for &v in &self.stack_v[at + 1..] {
                self.on_stack[v as usize] = NONE;
            }
            self.stack_v.truncate(at + 1);
            self.stack_h.truncate(at);
        }
        for &v in &self.stack_v {
            self.on_stack[v as usize] = NONE;
        }

        let here = match mode {
            Mode::Face { cell, .. } => Owner::Cell(cell),
            Mode::Outside { comp } => Owner::Outside(comp),
        };
        for &h in &self.walk {
            self.out[h as usize] = true;
            self.face[h as usize] = here.into();
        }
        for k in 0..self.walk.len() {
            let h = self.walk[k];
            if self.out[topo.twin[h as usize] as usize] {
                topo.remove_edge(h);
            }
        }
        Ok(())
    }

    /// Records the loop made of `stack_h[at..]` and the closing half-edge `h`.
    fn close_loop(&mut self, topo: &Topology, at: usize, h: u32, mode: Mode, is_main: bool) {
        let here = match mode {
            Mode::Face { cell, .. } => Owner::Cell(cell),
            Mode::Outside { comp } => Owner::Outside(comp),
        };
        let len = self.stack_h.len() - at + 1;
        let back = topo.twin[h as usize];
        if len == 2 && self.stack_h[at] == back && !is_main {
            // An edge walked there and back: a filament edge in this face.
            self.filament_owner[h.min(back) as usize] = here.into();
            self.tag[h as usize] = here.into();
            self.tag[back as usize] = here.into();
            return;
        }
        let span = Span {
            start: self.ring_buf.len() as u32,
            len: len as u32,
        };
        self.ring_buf.extend_from_slice(&self.stack_h[at..]);
        self.ring_buf.push(h);
        if is_main {
            let Mode::Face { parent, .. } = mode else {
                return;
            };
            for k in span.start as usize..self.ring_buf.len() {
                let x = self.ring_buf[k];
                self.tag[x as usize] = parent.into();
                let uses = &mut self.cycle_uses[x.min(topo.twin[x as usize]) as usize];
                *uses = uses.saturating_add(1);
            }
            self.cycles.push(RawCycle { span, parent });
        } else {
            for k in span.start as usize..self.ring_buf.len() {
                self.tag[self.ring_buf[k] as usize] = here.into();
            }
            self.loops.push(RawLoop { span, owner: here });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::ExtractionReport;
    use crate::params::CellParams;
    use polis_geom::{DVec2, PlanarGraph};

    fn run(g: &PlanarGraph<(), ()>) -> (Topology, Sweep) {
        let mut t = Topology::default();
        let mut r = ExtractionReport::default();
        t.build(g, &CellParams::default(), &|_| true, &mut r)
            .unwrap();
        let mut s = Sweep::default();
        s.run(&mut t).unwrap();
        (t, s)
    }

    /// A 4 × 4 grid with a dead end in every cell and a ring inside one cell.
    fn busy() -> PlanarGraph<(), ()> {
        let mut g = PlanarGraph::new();
        let mut id = Vec::new();
        for j in 0..4 {
            for i in 0..4 {
                id.push(
                    g.add_node(DVec2::new(f64::from(i) * 10.0, f64::from(j) * 10.0), ())
                        .unwrap(),
                );
            }
        }
        for j in 0..4 {
            for i in 0..4 {
                let k = j * 4 + i;
                if i < 3 {
                    g.add_edge(id[k], id[k + 1], ()).unwrap();
                }
                if j < 3 {
                    g.add_edge(id[k], id[k + 4], ()).unwrap();
                }
                if i < 3 && j < 3 {
                    let p = g.position(id[k]).unwrap() + DVec2::new(3.0, 2.0);
                    let d = g.add_node(p, ()).unwrap();
                    g.add_edge(id[k], d, ()).unwrap();
                }
            }
        }
        let ring: Vec<_> = [(14.0, 14.0), (18.0, 14.0), (18.0, 18.0), (14.0, 18.0)]
            .iter()
            .map(|&(x, y)| g.add_node(DVec2::new(x, y), ()).unwrap())
            .collect();
        for i in 0..4 {
            g.add_edge(ring[i], ring[(i + 1) % 4], ()).unwrap();
        }
        g
    }

    #[test]
    fn every_half_edge_is_walked_once_and_every_edge_removed() {
        let g = busy();
        let (t, s) = run(&g);
        assert_eq!(s.walked, 2 * g.edge_count());
        assert!(t.live.iter().all(|&l| !l));
        assert!(t.deg.iter().all(|&d| d == 0));
        assert_eq!(s.cycles.len(), 9 + 1);
        assert_eq!(s.components.len(), 2);
        // The island's outside was walked as component 1 and its cycle waits for it.
        let island = s
            .cycles
            .iter()
            .find(|c| {
                t.p(t.origin[s.ring_buf[c.span.start as usize] as usize]) == DVec2::new(14.0, 14.0)
            })
            .unwrap();
        assert_eq!(island.parent, Owner::Outside(1));
        assert_eq!(s.loops.len(), 2);
    }

    #[test]
    fn grid_cells_are_found_left_to_right() {
        let g = busy();
        let (t, s) = run(&g);
        let first_x: Vec<f64> = s
            .cycles
            .iter()
            .map(|c| t.p(t.origin[s.ring_buf[c.span.start as usize] as usize]).x)
            .collect();
        assert!(first_x.windows(2).all(|w| w[0] <= w[1]), "{first_x:?}");
        // Dead ends were detached inside their cells.
        let inside = s
            .filament_owner
            .iter()
            .filter(|o| matches!(o.get(), Owner::Cell(_)))
            .count();
        assert_eq!(inside, 9);
    }
}
