//! The error type of `polis-geom`.

use glam::DVec2;

/// Which ring of a [`PolygonWithHoles`](crate::PolygonWithHoles) an error is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Ring {
    /// The outer boundary.
    Outer,
    /// The hole with this index in [`PolygonWithHoles::holes`](crate::PolygonWithHoles::holes).
    Hole(usize),
}

impl std::fmt::Display for Ring {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Ring::Outer => f.write_str("outer ring"),
            Ring::Hole(i) => write!(f, "hole {i}"),
        }
    }
}

/// What is wrong with a piece of geometry handed to `polis-geom`.
///
/// Every variant names the offending vertices, edges or ids so the caller can find them.
/// Edge `i` of a ring runs from vertex `i` to vertex `(i + 1) % len`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GeomError {
    /// A coordinate is NaN or infinite.
    #[error(
        "vertex {index} has a non-finite coordinate ({point}); coordinates must be finite numbers"
    )]
    NonFinite {
        /// Index of the vertex.
        index: usize,
        /// The offending point.
        point: DVec2,
    },
    /// A coordinate is finite but too large to be handled exactly (see [`MAX_COORDINATE`](crate::MAX_COORDINATE)).
    #[error(
        "vertex {index} at {point} lies outside ±{limit} m; move the geometry closer to the origin"
    )]
    OutOfRange {
        /// Index of the vertex.
        index: usize,
        /// The offending point.
        point: DVec2,
        /// The limit that was exceeded, in metres.
        limit: f64,
    },
    /// Fewer than three distinct points.
    #[error("the ring has {distinct} distinct vertices; a polygon needs at least 3")]
    TooFewVertices {
        /// How many distinct vertices there are.
        distinct: usize,
    },
    /// Two vertices coincide.
    #[error("vertices {first} and {second} are the same point {point}; remove the repeat")]
    RepeatedVertex {
        /// The first index.
        first: usize,
        /// The second index.
        second: usize,
        /// The shared position.
        point: DVec2,
    },
    /// All vertices are collinear: the ring encloses no area.
    #[error("the ring encloses zero area (all vertices are collinear)")]
    ZeroArea,
    /// Two edges of a ring (or of two rings) intersect where they must not.
    #[error(
        "edge {first_edge} of the {first_ring} and edge {second_edge} of the {second_ring} intersect near {point}; rings must be simple and disjoint"
    )]
    SelfIntersection {
        /// Ring of the first edge.
        first_ring: Ring,
        /// Index of the first edge in its ring.
        first_edge: usize,
        /// Ring of the second edge.
        second_ring: Ring,
        /// Index of the second edge in its ring.
        second_edge: usize,
        /// A point where they meet.
        point: DVec2,
    },
    /// A hole lies (partly) outside the outer ring.
    #[error("hole {hole} is not inside the outer ring")]
    HoleOutside {
        /// Index of the hole.
        hole: usize,
    },
    /// A hole lies inside another hole.
    #[error("hole {inner} lies inside hole {outer}; holes must be disjoint")]
    NestedHoles {
        /// The hole that is inside.
        inner: usize,
        /// The hole that contains it.
        outer: usize,
    },
    /// An error in one ring of a polygon with holes.
    #[error("{ring}: {source}")]
    InRing {
        /// Which ring.
        ring: Ring,
        /// What is wrong with it.
        source: Box<GeomError>,
    },
    /// A graph id does not name a live node or edge.
    #[error("{what} id {index} does not name a live {what} of this graph")]
    InvalidId {
        /// "node" or "edge".
        what: &'static str,
        /// The raw index.
        index: u32,
    },
    /// An edge would have zero length (its two ends coincide, possibly after snapping).
    #[error(
        "the edge from {a} to {b} has zero length (after snapping); edges must join distinct points"
    )]
    ZeroLengthEdge {
        /// First end.
        a: DVec2,
        /// Second end.
        b: DVec2,
    },
    /// A parameter is outside its allowed range.
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The parameter's name.
        name: &'static str,
        /// Why it is invalid.
        reason: String,
    },
    /// An image could not be read as a grey-scale raster.
    #[error("could not read raster image: {0}")]
    Image(String),
    /// A raster's data does not have `width × height` values.
    #[error(
        "a raster of {width} × {height} texels needs width × height values but got {len}; give one value per texel, row by row"
    )]
    RasterSize {
        /// Texels per row.
        width: usize,
        /// Rows.
        height: usize,
        /// Number of values given.
        len: usize,
    },
    /// Two nodes of a graph are already joined by an edge.
    #[error(
        "nodes {a} and {b} are already joined by edge {existing}; a planar graph has no duplicate edges"
    )]
    DuplicateEdge {
        /// First node id.
        a: u32,
        /// Second node id.
        b: u32,
        /// The edge that joins them.
        existing: u32,
    },
    /// Two edges of a planar graph cross or overlap (share more than a common end).
    #[error(
        "edges {first} and {second} meet at {point} away from a common end; insert edges with `insert_segment` to keep the graph planar"
    )]
    EdgesIntersect {
        /// The edge with the smaller id.
        first: u32,
        /// The other edge.
        second: u32,
        /// A point they share.
        point: DVec2,
    },
    /// A node lies on another node or inside an edge it is not an end of.
    #[error(
        "node {node} at {point} lies on {what} {other}; snap it (e.g. `insert_point`) instead of adding it raw"
    )]
    NodeOnGeometry {
        /// The node.
        node: u32,
        /// Its position.
        point: DVec2,
        /// `"node"` or `"edge"`.
        what: &'static str,
        /// The node or edge it lies on.
        other: u32,
    },
    /// The internal bookkeeping of a graph is inconsistent (a bug, or a hand-edited file).
    #[error("graph is inconsistent: {0}")]
    GraphCorrupt(String),
    /// The constrained Delaunay triangulation failed on input that passed validation.
    #[error("triangulation failed: {0}; please report this polygon as a bug")]
    Triangulation(String),
    /// A mesh attribute array has the wrong length.
    #[error(
        "mesh attribute `{attribute}` has {len} entries but the mesh has {expected} vertices; give every vertex one entry"
    )]
    MeshAttributeLength {
        /// `"normals"` or `"uvs"`.
        attribute: &'static str,
        /// Its length.
        len: usize,
        /// The number of positions.
        expected: usize,
    },
    /// The index list does not describe whole triangles.
    #[error(
        "the mesh has {len} indices, which is not a multiple of 3; indices list whole triangles"
    )]
    MeshIndexCount {
        /// Number of indices.
        len: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "triangle {triangle} refers to vertex {index} but the mesh has {vertex_count} vertices"
    )]
    MeshIndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The bad index.
        index: u32,
        /// Number of vertices.
        vertex_count: usize,
    },
    /// A vertex attribute is NaN or infinite (or a normal is not of unit length).
    #[error(
        "vertex {vertex} has an invalid {attribute}: {reason}; positions, normals and uvs must be finite and normals of unit length"
    )]
    MeshInvalidVertex {
        /// `"position"`, `"normal"` or `"uv"`.
        attribute: &'static str,
        /// The vertex.
        vertex: usize,
        /// What is wrong.
        reason: &'static str,
    },
    /// A triangle has zero area (repeated or collinear corners, after rounding to `f32`).
    #[error(
        "triangle {triangle} has zero area (repeated or collinear corners); drop it or move its vertices apart"
    )]
    DegenerateTriangle {
        /// The triangle.
        triangle: usize,
    },
    /// A mesh meant to be a closed solid has an edge not shared by exactly two triangles.
    #[error(
        "the edge from {a} to {b} is used by {uses} triangles; a closed mesh uses every edge exactly twice"
    )]
    OpenEdge {
        /// One end (position).
        a: glam::Vec3,
        /// The other end (position).
        b: glam::Vec3,
        /// How many triangles use it.
        uses: usize,
    },
    /// Two triangles sharing an edge run it in the same direction: their windings disagree.
    #[error(
        "the two triangles on the edge from {a} to {b} are wound the same way; flip one so the surface is consistently oriented"
    )]
    InconsistentWinding {
        /// One end (position).
        a: glam::Vec3,
        /// The other end (position).
        b: glam::Vec3,
    },
    /// A scene object refers to another object that does not exist.
    #[error("{referrer} refers to {what} {index} but the scene has {len}; add it first")]
    SceneIndexOutOfRange {
        /// Who holds the reference, e.g. `"node 3"`.
        referrer: String,
        /// The kind of object referred to, e.g. `"mesh"`.
        what: &'static str,
        /// The bad index.
        index: usize,
        /// How many objects of that kind exist.
        len: usize,
    },
    /// The node graph is not a tree.
    #[error("node {node} {problem}; scene nodes must form a tree under the roots")]
    SceneNotATree {
        /// The offending node.
        node: usize,
        /// What is wrong: on a cycle, two parents, unreachable.
        problem: String,
    },
    /// A scene value (transform, material factor, image, metadata) is invalid.
    #[error("{what} is invalid: {reason}")]
    SceneInvalidValue {
        /// Which value, e.g. `"node 2 transform"`.
        what: String,
        /// What is wrong and how to fix it.
        reason: String,
    },
    /// One mesh of a scene is invalid.
    #[error("mesh {mesh}: {source}")]
    InMesh {
        /// The mesh index.
        mesh: usize,
        /// What is wrong with it.
        source: Box<GeomError>,
    },
}

/// Checks that a point is finite and within [`MAX_COORDINATE`](crate::MAX_COORDINATE).
///
/// `index` is only used to name the point in the error.
pub fn validate_point(index: usize, point: DVec2) -> Result<(), GeomError> {
    if !point.is_finite() {
        return Err(GeomError::NonFinite { index, point });
    }
    let limit = crate::MAX_COORDINATE;
    if point.x.abs() > limit || point.y.abs() > limit {
        return Err(GeomError::OutOfRange {
            index,
            point,
            limit,
        });
    }
    Ok(())
}
