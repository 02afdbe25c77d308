//! The 3-D turtle of ABOP §1.5 (and the commands of cpfg that draw).
//!
//! State: position `P`, an orthonormal right-handed frame heading `H`, left `L` and up `U`
//! (`H × L = U`), a width and a colour index. The default start is at the origin heading
//! along `+Y` with `U = +Z`, so 2-D L-systems draw in the XY plane and `+` turns
//! counter-clockwise (to the left), as in ABOP.
//!
//! | symbol | command | effect |
//! |---|---|---|
//! | `F(l)` `G(l)` | [`Command::Forward`] | move `l` (default [`TurtleOptions::step`]) along `H`, drawing a segment |
//! | `f(l)` `g(l)` | [`Command::Move`] | move without drawing |
//! | `+(a)` `-(a)` | turn left / right | rotate `H, L` about `U` by `a` degrees (default [`TurtleOptions::angle_degrees`]) |
//! | `&(a)` `^(a)` | pitch down / up | rotate `H, U` about `L` |
//! | `\(a)` `/(a)` | roll left / right | rotate `L, U` about `H` |
//! | `\|` | turn around | `H, L` negated |
//! | `$` | roll to vertical | `L = V × H / ‖V × H‖`, `U = H × L`, `V` = [`TurtleOptions::vertical`] |
//! | `[` `]` | push / pop | save and restore the whole state |
//! | `!(w)` | width | set width `w`; without a parameter decrease it by [`TurtleOptions::width_decrement`] |
//! | `'(c)` | colour | set colour index `c`; without a parameter increment it |
//! | `{` `.` `}` | polygon | start, record a vertex, emit |
//! | `@o(r)` | dot | a disc/sphere of radius `r` (default half the width) |
//!
//! Non-finite arguments (NaN, ±∞) are treated as 0 so that a bad parameter never poisons
//! the rest of the drawing; popping an empty stack is ignored and counted in
//! [`Turtle::unbalanced`].

use glam::{DVec2, DVec3};

use crate::command::Command;

/// Turtle configuration. Lengths are in the caller's units (metres in polis).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct TurtleOptions {
    /// Length of `F`/`f` without a parameter. Default: 1.0.
    pub step: f64,
    /// Angle of the rotation commands without a parameter, in degrees. Default: 90.0.
    pub angle_degrees: f64,
    /// Initial width. Default: 1.0.
    pub width: f64,
    /// Amount `!` without a parameter subtracts from the width (never below 0). Default: 0.1.
    pub width_decrement: f64,
    /// Initial heading (normalised; must not be parallel to `up`). Default: `+Y`.
    pub heading: DVec3,
    /// Initial up vector (made orthogonal to the heading). Default: `+Z`.
    pub up: DVec3,
    /// World vertical `V` used by `$`. Default: `+Y`.
    pub vertical: DVec3,
}

impl Default for TurtleOptions {
    fn default() -> Self {
        Self {
            step: 1.0,
            angle_degrees: 90.0,
            width: 1.0,
            width_decrement: 0.1,
            heading: DVec3::Y,
            up: DVec3::Z,
            vertical: DVec3::Y,
        }
    }
}

/// The turtle's state: what query and communication modules receive.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct TurtleState {
    /// Position `P`.
    pub position: DVec3,
    /// Heading `H` (unit).
    pub heading: DVec3,
    /// Left `L` (unit).
    pub left: DVec3,
    /// Up `U` (unit), `H × L`.
    pub up: DVec3,
    /// Current width.
    pub width: f64,
    /// Current colour index.
    pub colour: u32,
}

impl TurtleState {
    /// The start state for `options` (a degenerate heading/up pair falls back to `+Y`/`+Z`).
    pub fn initial(options: &TurtleOptions) -> Self {
        let mut h = options.heading.normalize_or_zero();
        if h == DVec3::ZERO || !h.is_finite() {
            h = DVec3::Y;
        }
        let mut u = (options.up - h * options.up.dot(h)).normalize_or_zero();
        if u == DVec3::ZERO || !u.is_finite() {
            u = h.any_orthonormal_vector();
        }
        let l = u.cross(h);
        Self {
            position: DVec3::ZERO,
            heading: h,
            left: l,
            up: u,
            width: if options.width.is_finite() {
                options.width
            } else {
                1.0
            },
            colour: 0,
        }
    }
}

/// A drawn line segment.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Segment {
    /// Start point.
    pub from: DVec3,
    /// End point.
    pub to: DVec3,
    /// Turtle width while drawing.
    pub width: f64,
    /// Turtle colour index while drawing.
    pub colour: u32,
}

/// A chain of segments sharing width and colour (see [`Geometry::polylines`]).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Polyline {
    /// The points, at least two.
    pub points: Vec<DVec3>,
    /// Width.
    pub width: f64,
    /// Colour index.
    pub colour: u32,
}

/// A polygon recorded with `{ . }`.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct TurtlePolygon {
    /// The recorded vertices, in order.
    pub vertices: Vec<DVec3>,
    /// Colour index when `}` was met.
    pub colour: u32,
}

/// A dot drawn with `@o`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Dot {
    /// Centre.
    pub centre: DVec3,
    /// Radius.
    pub radius: f64,
    /// Colour index.
    pub colour: u32,
}

/// Receives what the turtle draws. Every method defaults to doing nothing, so `()` is a
/// sink that discards everything.
pub trait TurtleSink {
    /// A segment drawn by `F`.
    fn segment(&mut self, _segment: &Segment) {}
    /// A polygon closed by `}`.
    fn polygon(&mut self, _vertices: &[DVec3], _colour: u32) {}
    /// A dot drawn by `@o`.
    fn dot(&mut self, _dot: &Dot) {}
}

impl TurtleSink for () {}

/// A ready sink that keeps everything.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Geometry {
    /// Segments in drawing order.
    pub segments: Vec<Segment>,
    /// Polygons in drawing order.
    pub polygons: Vec<TurtlePolygon>,
    /// Dots in drawing order.
    pub dots: Vec<Dot>,
}

impl TurtleSink for Geometry {
    fn segment(&mut self, segment: &Segment) {
        self.segments.push(*segment);
    }
    fn polygon(&mut self, vertices: &[DVec3], colour: u32) {
        self.polygons.push(TurtlePolygon {
            vertices: vertices.to_vec(),
            colour,
        });
    }
    fn dot(&mut self, dot: &Dot) {
        self.dots.push(*dot);
    }
}

impl Geometry {
    /// Joins consecutive segments that continue each other (same end point, width and
    /// colour) into polylines.
    pub fn polylines(&self) -> Vec<Polyline> {
        let mut out: Vec<Polyline> = Vec::new();
        for s in &self.segments {
            if let Some(last) = out.last_mut()
                && last.width == s.width
                && last.colour == s.colour
                && last.points.last() == Some(&s.from)
            {
                last.points.push(s.to);
                continue;
            }
            out.push(Polyline {
                points: vec![s.from, s.to],
                width: s.width,
                colour: s.colour,
            });
        }
        out
    }

    /// Bounding box `(min, max)` of all points, or `None` if nothing was drawn.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let pts = self
            .segments
            .iter()
            .flat_map(|s| [s.from, s.to])
            .chain(
                self.polygons
                    .iter()
                    .flat_map(|p| p.vertices.iter().copied()),
            )
            .chain(self.dots.iter().map(|d| d.centre));
        let mut b: Option<(DVec3, DVec3)> = None;
        for p in pts {
            b = Some(match b {
                None => (p, p),
                Some((lo, hi)) => (lo.min(p), hi.max(p)),
            });
        }
        b
    }
}

/// The turtle interpreter.
#[derive(Debug, Clone)]
pub struct Turtle {
    options: TurtleOptions,
    state: TurtleState,
    stack: Vec<TurtleState>,
    polygons: Vec<Vec<DVec3>>,
    unbalanced: usize,
}

#[inline]
fn finite_or_zero(v: f64) -> f64 {
    if v.is_finite() { v } else { 0.0 }
}

/// Rotates the pair `(a, b)` by `degrees` in its plane. The sine and cosine come from
/// glam, which the workspace builds with its `libm` feature, so turtle geometry is the same
/// on every platform.
#[inline]
fn rotate(a: DVec3, b: DVec3, degrees: f64) -> (DVec3, DVec3) {
    let cs = DVec2::from_angle(finite_or_zero(degrees).to_radians());
    let (s, c) = (cs.y, cs.x);
    (a * c + b * s, b * c - a * s)
}

impl Turtle {
    /// A turtle in its initial state.
    pub fn new(options: TurtleOptions) -> Self {
        Self {
            state: TurtleState::initial(&options),
            options,
            stack: Vec::new(),
            polygons: Vec::new(),
            unbalanced: 0,
        }
    }

    /// Back to the initial state (keeps allocations).
    pub fn reset(&mut self) {
        self.state = TurtleState::initial(&self.options);
        self.stack.clear();
        self.polygons.clear();
        self.unbalanced = 0;
    }

    /// The current state.
    #[inline]
    pub fn state(&self) -> &TurtleState {
        &self.state
    }

    /// The options.
    pub fn options(&self) -> &TurtleOptions {
        &self.options
    }

    /// How many `]` met an empty stack so far.
    pub fn unbalanced(&self) -> usize {
        self.unbalanced
    }

    /// Current branch depth (pushed states).
    pub fn depth(&self) -> usize {
        self.stack.len()
    }

    /// Executes one command, reporting drawn geometry to `sink`.
    pub fn apply<S: TurtleSink + ?Sized>(&mut self, command: Command, sink: &mut S) {
        let o = &self.options;
        let st = &mut self.state;
        let angle = |a: Option<f64>| a.unwrap_or(o.angle_degrees);
        match command {
            Command::Forward(l) => {
                let from = st.position;
                st.position += st.heading * finite_or_zero(l.unwrap_or(o.step));
                sink.segment(&Segment {
                    from,
                    to: st.position,
                    width: st.width,
                    colour: st.colour,
                });
            }
            Command::Move(l) => st.position += st.heading * finite_or_zero(l.unwrap_or(o.step)),
            Command::TurnLeft(a) => (st.heading, st.left) = rotate(st.heading, st.left, angle(a)),
            Command::TurnRight(a) => {
                (st.heading, st.left) = rotate(st.heading, st.left, -angle(a));
            }
            Command::PitchDown(a) => {
                let (h, down) = rotate(st.heading, -st.up, angle(a));
                (st.heading, st.up) = (h, -down);
            }
            Command::PitchUp(a) => {
                let (h, down) = rotate(st.heading, -st.up, -angle(a));
                (st.heading, st.up) = (h, -down);
            }
            Command::RollRight(a) => (st.left, st.up) = rotate(st.left, st.up, angle(a)),
            Command::RollLeft(a) => (st.left, st.up) = rotate(st.left, st.up, -angle(a)),
            Command::TurnAround => {
                st.heading = -st.heading;
                st.left = -st.left;
            }
            Command::RollToVertical => {
                let l = o.vertical.cross(st.heading).normalize_or_zero();
                if l != DVec3::ZERO && l.is_finite() {
                    st.left = l;
                    st.up = st.heading.cross(l);
                }
            }
            Command::Push => self.stack.push(*st),
            Command::Pop => match self.stack.pop() {
                Some(s) => *st = s,
                None => self.unbalanced += 1,
            },
            Command::Width(w) => {
                st.width = match w {
                    Some(w) => finite_or_zero(w),
                    None => (st.width - finite_or_zero(o.width_decrement)).max(0.0),
                };
            }
            Command::Colour(c) => {
                st.colour = match c {
                    Some(c) => finite_or_zero(c).clamp(0.0, u32::MAX as f64) as u32,
                    None => st.colour.saturating_add(1),
                };
            }
            Command::PolygonStart => self.polygons.push(Vec::new()),
            Command::PolygonVertex => {
                if let Some(p) = self.polygons.last_mut() {
                    p.push(st.position);
                }
            }
            Command::PolygonEnd => {
                if let Some(p) = self.polygons.pop() {
                    sink.polygon(&p, st.colour);
                }
            }
            Command::Dot(r) => sink.dot(&Dot {
                centre: st.position,
                radius: finite_or_zero(r.unwrap_or(st.width * 0.5)),
                colour: st.colour,
            }),
            Command::None | Command::Cut | Command::Query(_) | Command::Communicate => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn frame_stays_right_handed() {
        let mut t = Turtle::new(TurtleOptions::default());
        let cmds = [
            Command::TurnLeft(Some(33.0)),
            Command::PitchDown(Some(12.0)),
            Command::RollRight(Some(71.0)),
            Command::PitchUp(None),
            Command::RollLeft(Some(5.0)),
            Command::TurnAround,
            Command::RollToVertical,
        ];
        for c in cmds {
            t.apply(c, &mut ());
            let s = t.state();
            assert!(close(s.heading.cross(s.left), s.up), "{c:?}");
            assert!((s.heading.length() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn turns_pitches_and_draws() {
        let mut g = Geometry::default();
        let mut t = Turtle::new(TurtleOptions::default());
        t.apply(Command::TurnLeft(None), &mut g);
        assert!(close(t.state().heading, DVec3::NEG_X));
        t.apply(Command::Forward(Some(2.0)), &mut g);
        assert!(close(t.state().position, DVec3::new(-2.0, 0.0, 0.0)));
        t.apply(Command::PitchUp(None), &mut g);
        assert!(close(t.state().heading, DVec3::Z));
        t.apply(Command::Push, &mut g);
        t.apply(Command::Forward(None), &mut g);
        t.apply(Command::Pop, &mut g);
        t.apply(Command::Pop, &mut g);
        assert_eq!(t.unbalanced(), 1);
        assert!(close(t.state().position, DVec3::new(-2.0, 0.0, 0.0)));
        assert_eq!(g.segments.len(), 2);
        assert_eq!(g.polylines().len(), 1);
        t.apply(Command::Forward(Some(f64::NAN)), &mut g);
        assert!(t.state().position.is_finite());
    }

    #[test]
    fn width_colour_polygon_dot() {
        let mut g = Geometry::default();
        let mut t = Turtle::new(TurtleOptions::default());
        t.apply(Command::Width(None), &mut g);
        assert!((t.state().width - 0.9).abs() < 1e-12);
        t.apply(Command::Colour(None), &mut g);
        t.apply(Command::Colour(Some(-3.0)), &mut g);
        assert_eq!(t.state().colour, 0);
        t.apply(Command::PolygonStart, &mut g);
        for _ in 0..3 {
            t.apply(Command::PolygonVertex, &mut g);
            t.apply(Command::Move(None), &mut g);
            t.apply(Command::TurnLeft(Some(120.0)), &mut g);
        }
        t.apply(Command::PolygonEnd, &mut g);
        t.apply(Command::Dot(None), &mut g);
        assert_eq!(g.polygons[0].vertices.len(), 3);
        assert_eq!(g.dots[0].radius, 0.45);
    }
}
