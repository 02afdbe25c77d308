//! The report's city map laid over a cell: a square grid in metres ([`Frame`]), one
//! [`Site`] per grid point, and the cell's boundary and maps that decide where a street
//! may go ([`Ground`]).

use polis_geom::spatial::{SegmentIndex, SpatialIndex};
use polis_geom::{DVec2, PointLocation, PolygonWithHoles};

use super::error::{GridError, Result};
use super::maps::GridMaps;

/// A grid direction. `East` runs along the grid's first axis `u`, `North` along `v`
/// (`u` turned 90° counter-clockwise), so turning left is `+1` and right is `-1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Dir {
    East = 0,
    North = 1,
    West = 2,
    South = 3,
}

impl Dir {
    pub(crate) const ALL: [Dir; 4] = [Dir::East, Dir::North, Dir::West, Dir::South];

    fn from_index(i: u8) -> Dir {
        Dir::ALL[usize::from(i & 3)]
    }
    pub(crate) fn left(self) -> Dir {
        Dir::from_index(self as u8 + 1)
    }
    pub(crate) fn right(self) -> Dir {
        Dir::from_index(self as u8 + 3)
    }
    pub(crate) fn opposite(self) -> Dir {
        Dir::from_index(self as u8 + 2)
    }
    /// The bit of this direction in [`Site::links`].
    pub(crate) fn bit(self) -> u8 {
        1 << (self as u8)
    }
    /// Grid steps `(di, dj)`.
    pub(crate) fn delta(self) -> (i64, i64) {
        match self {
            Dir::East => (1, 0),
            Dir::North => (0, 1),
            Dir::West => (-1, 0),
            Dir::South => (0, -1),
        }
    }
}

/// The grid in the plane: point `(i, j)` is `origin + i·s·u + j·s·v`, for `i` in
/// `imin..imin + width` and `j` in `jmin..jmin + height` (the cell's bounding box plus a
/// margin of one step).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame {
    pub(crate) origin: DVec2,
    pub(crate) u: DVec2,
    pub(crate) v: DVec2,
    pub(crate) step: f64,
    imin: i64,
    jmin: i64,
    pub(crate) width: usize,
    pub(crate) height: usize,
}

impl Frame {
    /// The grid with first axis `u` (a unit vector) through `origin`, covering `cell`.
    pub(crate) fn covering(
        cell: &PolygonWithHoles,
        origin: DVec2,
        u: DVec2,
        step: f64,
        max_points: u64,
    ) -> Result<Frame> {
        let v = u.perp();
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for p in cell.outer.points() {
            let d = *p - origin;
            let g = DVec2::new(d.dot(u), d.dot(v)) / step;
            lo = lo.min(g);
            hi = hi.max(g);
        }
        let (lo, hi) = ((lo.floor() - 1.0), (hi.ceil() + 1.0));
        let extent = hi - lo + 1.0;
        let points = extent.x * extent.y;
        if !points.is_finite() || points > max_points as f64 {
            return Err(GridError::TooManyLatticePoints {
                points: if points.is_finite() {
                    points as u64
                } else {
                    u64::MAX
                },
                max: max_points,
            });
        }
        Ok(Frame {
            origin,
            u,
            v,
            step,
            imin: lo.x as i64,
            jmin: lo.y as i64,
            width: extent.x as usize,
            height: extent.y as usize,
        })
    }

    /// Number of grid points.
    pub(crate) fn len(&self) -> usize {
        self.width * self.height
    }

    /// The site index of grid point `(i, j)`, if it is on the grid.
    pub(crate) fn index(&self, i: i64, j: i64) -> Option<usize> {
        let (x, y) = (i - self.imin, j - self.jmin);
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            return None;
        }
        Some(y as usize * self.width + x as usize)
    }

    /// The grid coordinates `(i, j)` of site `k`.
    pub(crate) fn coords(&self, k: usize) -> (i64, i64) {
        (
            (k % self.width) as i64 + self.imin,
            (k / self.width) as i64 + self.jmin,
        )
    }

    /// The neighbour of site `k` one step towards `d`.
    pub(crate) fn neighbor(&self, k: usize, d: Dir) -> Option<usize> {
        let (i, j) = self.coords(k);
        let (di, dj) = d.delta();
        self.index(i + di, j + dj)
    }

    /// The position of site `k`, metres.
    pub(crate) fn position(&self, k: usize) -> DVec2 {
        let (i, j) = self.coords(k);
        self.origin + self.u * (i as f64 * self.step) + self.v * (j as f64 * self.step)
    }

    /// The unit vector of `d` in the plane.
    pub(crate) fn vector(&self, d: Dir) -> DVec2 {
        match d {
            Dir::East => self.u,
            Dir::North => self.v,
            Dir::West => -self.u,
            Dir::South => -self.v,
        }
    }

    /// `p` in grid units `(a, b)` (real-valued `(i, j)`).
    pub(crate) fn grid_coords(&self, p: DVec2) -> DVec2 {
        let d = p - self.origin;
        DVec2::new(d.dot(self.u), d.dot(self.v)) / self.step
    }
}

/// One grid point of the report's city map (its `CityNode`).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Site {
    /// The point is a street.
    pub(crate) street: bool,
    /// Streets to the neighbours, one bit per [`Dir`].
    pub(crate) links: u8,
    /// The point has a street running on to the cell boundary.
    pub(crate) joined: bool,
    /// A street running on to the boundary passes through this point (which is too near
    /// the boundary to be a street itself); no other may pass, so such streets never
    /// cross each other.
    pub(crate) passed: bool,
    /// Queue pop at which the point became a street.
    pub(crate) born: u32,
}

impl Site {
    /// Number of streets meeting here (a boundary join counts as one).
    pub(crate) fn degree(&self) -> u32 {
        self.links.count_ones() + u32::from(self.joined)
    }
}

/// The smallest sine of the angle at which a street may run on to the boundary (about
/// 11.5°). A street from a grid point clear of the boundary meets it at a sine of at
/// least `clearance / (step + clearance)` anyway; shallower hits arise only where a grid
/// line runs into a reflex corner along one of its edges, and such a street would run
/// along the boundary, so it is refused.
pub(crate) const MIN_JOIN_SINE: f64 = 0.2;

/// The cell's boundary rings, its filaments and the maps: where streets may go.
pub(crate) struct Ground<'a> {
    cell: &'a PolygonWithHoles,
    /// Every boundary and filament segment, by key.
    index: SegmentIndex<u32>,
    /// The same segments, indexed by key.
    walls: Vec<(DVec2, DVec2)>,
    maps: GridMaps<'a>,
    legality_step: f64,
}

impl<'a> Ground<'a> {
    pub(crate) fn new(
        cell: &'a PolygonWithHoles,
        filaments: &[[DVec2; 2]],
        maps: GridMaps<'a>,
        legality_step: f64,
    ) -> Result<Ground<'a>> {
        let mut index = SegmentIndex::default();
        let rings = cell.rings().flat_map(|(_, ring)| ring.edges());
        let walls: Vec<_> = rings
            .chain(filaments.iter().map(|&[a, b]| (a, b)))
            .collect();
        for (key, &(a, b)) in (0u32..).zip(&walls) {
            index
                .insert_segment(key, a, b)
                .map_err(GridError::InvalidCell)?;
        }
        Ok(Ground {
            cell,
            index,
            walls,
            maps,
            legality_step,
        })
    }

    /// Whether `p` is strictly inside the cell (exact point location).
    pub(crate) fn inside(&self, p: DVec2) -> bool {
        self.cell.locate(p) == PointLocation::Inside
    }

    /// Whether no boundary or filament segment comes within `clearance` of `p`.
    pub(crate) fn clear(&self, p: DVec2, clearance: f64) -> bool {
        self.index.nearest_segment(p, clearance).is_none()
    }

    /// The first point of the boundary or a filament on the segment `a–b` (exact
    /// crossing decision; the point is computed afterwards), and whether a street may
    /// end there: not if `a–b` meets that wall at less than [`MIN_JOIN_SINE`].
    pub(crate) fn first_hit(&self, a: DVec2, b: DVec2) -> Option<(DVec2, bool)> {
        let hit = self.index.first_crossing(a, b, |_| true)?;
        let point = a + (b - a) * hit.t;
        let steep = self.walls.get(hit.key as usize).is_some_and(|&(w0, w1)| {
            let (d, w) = ((b - a).normalize_or_zero(), (w1 - w0).normalize_or_zero());
            d.perp_dot(w).abs() >= MIN_JOIN_SINE
        });
        Some((point, steep))
    }

    /// Whether the straight street `a–b` stays out of water and parks: every sample,
    /// at most `legality_step` apart and including both ends, has both maps below 0.5
    /// (NaN counts as illegal).
    pub(crate) fn legal(&self, a: DVec2, b: DVec2) -> bool {
        let n = ((a.distance(b) / self.legality_step).ceil() as usize).max(1);
        if self.maps.water.is_none() && self.maps.parks.is_none() {
            return true;
        }
        (0..=n).all(|k| !self.maps.blocked_at(a.lerp(b, k as f64 / n as f64)))
    }
}
