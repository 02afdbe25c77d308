//! The turtle command vocabulary shared by typed and text modules.

/// Which turtle vector a query module asks for (ABOP's `?P ?H ?U ?L`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum QueryKind {
    /// `?P`: the position.
    Position,
    /// `?H`: the heading vector.
    Heading,
    /// `?U`: the up vector.
    Up,
    /// `?L`: the left vector.
    Left,
}

/// What a module means to the turtle and to the derivation engine.
///
/// `Option<f64>` arguments are the module's first parameter; `None` means "use the turtle's
/// configured default" ([`TurtleOptions`](crate::TurtleOptions)).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum Command {
    /// No turtle meaning (an ordinary symbol such as `A`).
    #[default]
    None,
    /// `F(l)`: move forward and draw a segment.
    Forward(Option<f64>),
    /// `f(l)`: move forward without drawing.
    Move(Option<f64>),
    /// `+(a)`: turn left around the up vector (degrees).
    TurnLeft(Option<f64>),
    /// `-(a)`: turn right around the up vector (degrees).
    TurnRight(Option<f64>),
    /// `&(a)`: pitch down around the left vector (degrees).
    PitchDown(Option<f64>),
    /// `^(a)`: pitch up around the left vector (degrees).
    PitchUp(Option<f64>),
    /// `\(a)`: roll left around the heading (degrees).
    RollLeft(Option<f64>),
    /// `/(a)`: roll right around the heading (degrees).
    RollRight(Option<f64>),
    /// `|`: turn around (180° about the up vector).
    TurnAround,
    /// `$`: roll so that the left vector is horizontal (ABOP §1.5: `L = V × H / |V × H|`, `V` = world up).
    RollToVertical,
    /// `[`: push the turtle state; starts a branch.
    Push,
    /// `]`: pop the turtle state; ends a branch.
    Pop,
    /// `%`: cut — the rest of the current branch is removed in the next derivation step.
    Cut,
    /// `!(w)`: set the width to `w`, or without a parameter decrease it by the configured decrement.
    Width(Option<f64>),
    /// `'(c)`: set the colour index to `c`, or without a parameter increment it.
    Colour(Option<f64>),
    /// `{`: start a polygon.
    PolygonStart,
    /// `.`: record the turtle position as a polygon vertex.
    PolygonVertex,
    /// `}`: close and emit the current polygon.
    PolygonEnd,
    /// `@o(r)`: a dot (disc or sphere) of radius `r` (default: half the width).
    Dot(Option<f64>),
    /// `?P ?H ?U ?L`: a query module, filled from the turtle state between steps.
    Query(QueryKind),
    /// `?E` (or any registered symbol): a communication module handed to the
    /// [`Environment`](crate::Environment) between steps.
    Communicate,
}

/// How a module takes part in the branching structure of the string.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ModuleKind {
    /// An ordinary module.
    Plain,
    /// `[`.
    BranchOpen,
    /// `]`.
    BranchClose,
    /// `%`.
    Cut,
}

impl Command {
    /// The structural kind of a module with this command.
    #[inline]
    pub fn kind(self) -> ModuleKind {
        match self {
            Command::Push => ModuleKind::BranchOpen,
            Command::Pop => ModuleKind::BranchClose,
            Command::Cut => ModuleKind::Cut,
            _ => ModuleKind::Plain,
        }
    }
}
