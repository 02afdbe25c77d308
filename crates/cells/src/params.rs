//! [`CellParams`]: the options of cell extraction.

/// What to do with two or more nodes at exactly the same position.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum CoincidentNodes {
    /// Merge them into the one with the smallest id, drop edges that become duplicates,
    /// and list both in the [`ExtractionReport`](crate::ExtractionReport).
    #[default]
    Merge,
    /// Fail with [`Error::CoincidentNodes`](crate::Error::CoincidentNodes).
    Reject,
}

/// Options of [`extract_with`](crate::extract_with) and
/// [`CellExtractor::extract`](crate::CellExtractor::extract).
///
/// Neither option changes the cells of a valid planar graph: they decide how invalid
/// input is treated and what is checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct CellParams {
    /// Nodes at exactly the same position (no tolerance: snapping nearby points is the job
    /// of the graph's planar insertion). Default: [`CoincidentNodes::Merge`].
    pub coincident_nodes: CoincidentNodes,
    /// Verify that no two edges cross or overlap and that no node lies inside an edge
    /// before extracting, and fail with [`Error::NotPlanar`](crate::Error::NotPlanar)
    /// naming the offending edges. An exact `O(n log n)` line sweep (Shamos–Hoey), about a
    /// quarter of the extraction's time. Skipped, whatever this says, for graphs that are
    /// planar by construction
    /// ([`PlanarGraph::is_planar_by_construction`](polis_geom::PlanarGraph::is_planar_by_construction):
    /// built only with planar insertion and removals); switch it off only for other graphs
    /// known to be planar.
    /// On a non-planar graph without the check the output is unspecified (but no panic).
    /// Default: `true`.
    pub check_planarity: bool,
}

impl Default for CellParams {
    fn default() -> Self {
        CellParams {
            coincident_nodes: CoincidentNodes::Merge,
            check_planarity: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults() {
        let p = CellParams::default();
        assert_eq!(p.coincident_nodes, CoincidentNodes::Merge);
        assert!(p.check_planarity);
    }

    #[cfg(feature = "serde")]
    #[test]
    fn serde_round_trip_and_defaults_for_missing_fields() {
        let p = CellParams {
            coincident_nodes: CoincidentNodes::Reject,
            check_planarity: false,
        };
        let s = serde_json::to_string(&p).unwrap();
        assert_eq!(serde_json::from_str::<CellParams>(&s).unwrap(), p);
        let partial: CellParams = serde_json::from_str(r#"{"check_planarity":false}"#).unwrap();
        assert_eq!(partial.coincident_nodes, CoincidentNodes::Merge);
        assert!(!partial.check_planarity);
    }
}
