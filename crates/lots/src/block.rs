//! Blocks: a cell inset by half the width of each bounding road, with a footpath strip
//! along its boundary (Kelly 2008 §4.4.1; Parish & Müller 2001 §4.1).

use polis_geom::polygon::locate_in_ring;
use polis_geom::{DVec2, PointLocation, Polygon, PolygonWithHoles};

use crate::LotsError;
use crate::error::check_positive;
use crate::inset::{Inset, InsetRing, InsetShape};
use crate::polygon_split::{Region, TaggedRing};

/// A cell as this stage sees it: a region of the road network and the width of the road
/// along each of its edges. A plain struct: build it by hand or from `polis-cells`.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Cell {
    /// A stable id (used to name the blocks and seed their lots).
    pub id: u64,
    /// The cell boundary: road centre lines, counter-clockwise, holes clockwise.
    pub polygon: PolygonWithHoles,
    /// Full width in metres of the road along each edge, ring by ring (outer ring first).
    pub road_widths: Vec<f64>,
}

/// Parameters of the block stage.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct BlockParams {
    /// Width of the footpath strip along the block boundary, metres (0 = no footpath).
    /// Default: 2.5.
    pub footpath_width: f64,
}

impl Default for BlockParams {
    fn default() -> Self {
        BlockParams {
            footpath_width: 2.5,
        }
    }
}

impl BlockParams {
    /// Checks every field against its documented range (`footpath_width` finite and
    /// ≥ 0).
    ///
    /// # Errors
    /// [`LotsError::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<(), LotsError> {
        let fw = self.footpath_width;
        if !(fw.is_finite() && fw >= 0.0) {
            return Err(LotsError::InvalidParameter {
                name: "footpath_width",
                reason: format!("{fw} m; it must be finite and not negative"),
            });
        }
        Ok(())
    }
}

/// A ring with the accumulated boundary length at each vertex, for texture coordinates.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct TexturedRing {
    /// The vertices, with the first repeated at the end so the last length is the perimeter.
    pub points: Vec<DVec2>,
    /// Boundary length from `points[0]` to each vertex, metres.
    pub length: Vec<f64>,
}

impl TexturedRing {
    fn new(ring: &[DVec2]) -> Self {
        let mut points: Vec<DVec2> = ring.to_vec();
        if let Some(&first) = ring.first() {
            points.push(first);
        }
        let mut length = Vec::with_capacity(points.len());
        let mut acc = 0.0;
        for (i, p) in points.iter().enumerate() {
            if i > 0 {
                acc += p.distance(points[i - 1]);
            }
            length.push(acc);
        }
        TexturedRing { points, length }
    }
}

/// The footpath: the strip between a block's boundary and its inset by the footpath width.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Footpath {
    /// The strip as polygons with holes.
    pub strips: Vec<PolygonWithHoles>,
    /// Every boundary ring of the strip (the kerb and the inner edge) with accumulated
    /// lengths.
    pub rings: Vec<TexturedRing>,
}

/// One block: a connected piece of a cell after insetting by half the road widths.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Block {
    /// The cell it came from.
    pub cell_id: u64,
    /// Index of this piece among the cell's blocks (a cell may fall apart into several).
    pub piece: usize,
    /// The block: the cell inset by half of each edge's road width.
    pub polygon: PolygonWithHoles,
    /// The footpath along the block's boundary.
    pub footpath: Footpath,
    /// The land inside the footpath, ready for lot subdivision. Every edge faces a street
    /// (through the footpath).
    pub parcels: Vec<Region>,
}

impl Block {
    /// A stable id for this block: the cell id and the piece index mixed.
    pub fn id(&self) -> u64 {
        self.cell_id
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(self.piece as u64)
    }
}

/// Builds the blocks of a cell.
///
/// # Errors
/// An invalid cell polygon, a road width per edge that is missing or not positive, or a
/// negative footpath width.
pub fn blocks(cell: &Cell, params: &BlockParams) -> Result<Vec<Block>, LotsError> {
    params.validate()?;
    let fw = params.footpath_width;
    let total: usize = cell.polygon.rings().map(|(_, r)| r.len()).sum();
    if cell.road_widths.len() != total {
        return Err(LotsError::EdgeCountMismatch {
            what: "road widths",
            expected: total,
            got: cell.road_widths.len(),
        });
    }
    for (e, &w) in cell.road_widths.iter().enumerate() {
        check_positive("road width", e, w)?;
    }
    let half: Vec<f64> = cell.road_widths.iter().map(|w| 0.5 * w).collect();
    let mut worker = Inset::new();
    let pieces = worker.shapes(&cell.polygon, Some(&half), 1.0)?;
    let mut out = Vec::with_capacity(pieces.len());
    for (piece, shape) in pieces.iter().enumerate() {
        let polygon = shape.to_polygon();
        let inner: Vec<InsetShape> = if fw > 0.0 {
            worker.shapes(&polygon, None, fw)?
        } else {
            vec![shape.clone()]
        };
        let footpath = if fw > 0.0 {
            footpath(&polygon, &inner)
        } else {
            Footpath {
                strips: Vec::new(),
                rings: Vec::new(),
            }
        };
        let parcels = inner.iter().map(parcel).collect();
        out.push(Block {
            cell_id: cell.id,
            piece,
            polygon,
            footpath,
            parcels,
        });
    }
    Ok(out)
}

fn parcel(shape: &InsetShape) -> Region {
    let tag = |r: &InsetRing| TaggedRing {
        points: r.points.clone(),
        street: vec![true; r.points.len()],
    };
    Region {
        outer: tag(&shape.outer),
        holes: shape.holes.iter().map(tag).collect(),
    }
}

/// The strip between the block and its inner inset, assembled from all boundary rings.
fn footpath(block: &PolygonWithHoles, inner: &[InsetShape]) -> Footpath {
    let mut ccw: Vec<Vec<DVec2>> = vec![block.outer.points().to_vec()];
    let mut cw: Vec<Vec<DVec2>> = block.holes.iter().map(|h| h.points().to_vec()).collect();
    for s in inner {
        let mut o = s.outer.points.clone();
        o.reverse();
        cw.push(o);
        for h in &s.holes {
            let mut r = h.points.clone();
            r.reverse();
            ccw.push(r);
        }
    }
    let rings = ccw
        .iter()
        .chain(&cw)
        .map(|r| TexturedRing::new(r))
        .collect();
    let mut strips: Vec<PolygonWithHoles> = ccw
        .into_iter()
        .map(|r| PolygonWithHoles::new(Polygon::new(r), Vec::new()))
        .collect();
    for h in cw {
        let probe = h[0];
        let mut best: Option<(usize, f64)> = None;
        for (i, s) in strips.iter().enumerate() {
            if locate_in_ring(s.outer.points(), probe) != PointLocation::Outside {
                let a = s.outer.area();
                if best.is_none_or(|(_, b)| a < b) {
                    best = Some((i, a));
                }
            }
        }
        if let Some((i, _)) = best {
            strips[i].holes.push(Polygon::new(h));
        }
    }
    Footpath { strips, rings }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn square_cell() {
        let cell = Cell {
            id: 7,
            polygon: Polygon::rect(v(0., 0.), v(100., 100.)).into(),
            road_widths: vec![10.0, 20.0, 10.0, 20.0],
        };
        let b = blocks(&cell, &BlockParams::default()).unwrap();
        assert_eq!(b.len(), 1);
        // Half widths 5, 10, 5, 10: (100 - 10 - 10) by (100 - 5 - 5).
        assert!((b[0].polygon.area() - 80.0 * 90.0).abs() < 1e-9);
        let parcel_area: f64 = b[0].parcels.iter().map(Region::area).sum();
        assert!((parcel_area - 75.0 * 85.0).abs() < 1e-9);
        let strip: f64 = b[0]
            .footpath
            .strips
            .iter()
            .map(PolygonWithHoles::area)
            .sum();
        assert!((strip + parcel_area - b[0].polygon.area()).abs() < 1e-9);
        for s in &b[0].footpath.strips {
            assert!(s.validate().is_ok());
        }
        let kerb = &b[0].footpath.rings[0];
        assert!((kerb.length.last().unwrap() - 2.0 * (80.0 + 90.0)).abs() < 1e-9);
        assert_eq!(kerb.points.len(), 5);
    }

    #[test]
    fn errors() {
        let mut cell = Cell {
            id: 0,
            polygon: Polygon::rect(v(0., 0.), v(10., 10.)).into(),
            road_widths: vec![1.0; 3],
        };
        assert!(blocks(&cell, &BlockParams::default()).is_err());
        cell.road_widths = vec![1.0, 1.0, f64::NAN, 1.0];
        assert!(blocks(&cell, &BlockParams::default()).is_err());
        cell.road_widths = vec![1.0; 4];
        let bad = BlockParams {
            footpath_width: -1.0,
        };
        assert!(blocks(&cell, &bad).is_err());
        // A cell too narrow for its roads has no block.
        cell.road_widths = vec![30.0; 4];
        assert!(blocks(&cell, &BlockParams::default()).unwrap().is_empty());
    }
}
