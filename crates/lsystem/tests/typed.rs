//! The typed front end: ABOP classics and engine semantics with closure productions.
#![allow(clippy::unwrap_used)]

use polis_lsystem::{
    Command, ContextItem, Derivation, DeriveOptions, Environment, Geometry, LsystemError, Module,
    Production, QueryKind, TurtleState, TypedRules,
};

#[derive(Clone, Debug, PartialEq)]
enum M {
    A,
    B,
    Fa,
    Fb,
    F(f64),
    Plus,
    Minus,
    Open,
    Close,
    Cut,
    X(f64),
    P(f64, f64),
    E(f64),
}

const A: u32 = 0;
const B: u32 = 1;
const F: u32 = 4;
const PLUS: u32 = 5;
const MINUS: u32 = 6;
const X: u32 = 10;

impl Module for M {
    fn symbol(&self) -> u32 {
        match self {
            M::A => 0,
            M::B => 1,
            M::Fa => 2,
            M::Fb => 3,
            M::F(_) => 4,
            M::Plus => 5,
            M::Minus => 6,
            M::Open => 7,
            M::Close => 8,
            M::Cut => 9,
            M::X(_) => 10,
            M::P(..) => 11,
            M::E(_) => 12,
        }
    }
    fn command(&self) -> Command {
        match self {
            M::F(l) => Command::Forward(Some(*l)),
            M::Plus => Command::TurnLeft(None),
            M::Minus => Command::TurnRight(None),
            M::Open => Command::Push,
            M::Close => Command::Pop,
            M::Cut => Command::Cut,
            M::P(..) => Command::Query(QueryKind::Position),
            M::E(_) => Command::Communicate,
            _ => Command::None,
        }
    }
    fn fill_query(&mut self, kind: QueryKind, state: &TurtleState) {
        if let (M::P(x, y), QueryKind::Position) = (self, kind) {
            *x = state.position.x;
            *y = state.position.y;
        }
    }
}

fn algae() -> TypedRules<'static, M> {
    let mut r = TypedRules::new();
    r.add(Production::new(A, |_, o| o.extend([M::A, M::B])))
        .unwrap()
        .add(Production::new(B, |_, o| o.push(M::A)))
        .unwrap();
    r
}

#[test]
fn algae_lengths_are_fibonacci() {
    let mut d = Derivation::new(algae(), vec![M::B], DeriveOptions::default());
    let (mut a, mut b) = (1usize, 1usize);
    for n in 1..=25 {
        let r = d.step().unwrap();
        assert_eq!(r.len, b, "step {n}");
        (a, b) = (b, a + b);
    }
    let mut d = Derivation::new(algae(), vec![M::B], DeriveOptions::default());
    d.derive(4).unwrap();
    assert_eq!(d.string(), &vec![M::A, M::B, M::A, M::A, M::B]);
}

/// ABOP §1.8 (acropetal signal propagation): `#ignore + -`, ω: `Fb[+Fa]Fa[-Fa]Fa[+Fa]Fa`,
/// `b < a → b`, `b → a`.
fn signal_string(s: &str) -> Vec<M> {
    let mut out = Vec::new();
    let cs: Vec<char> = s.chars().collect();
    let mut i = 0;
    while i < cs.len() {
        match cs[i] {
            'F' => {
                out.push(if cs[i + 1] == 'a' { M::Fa } else { M::Fb });
                i += 1;
            }
            '+' => out.push(M::Plus),
            '-' => out.push(M::Minus),
            '[' => out.push(M::Open),
            ']' => out.push(M::Close),
            c => panic!("{c}"),
        }
        i += 1;
    }
    out
}

#[test]
fn signal_propagation_is_acropetal() {
    // Fa / Fb are single modules here (an internode carrying the signal state).
    let mut r = TypedRules::new();
    r.add(Production::new(2, |_, o| o.push(M::Fb)).left([3]))
        .unwrap();
    r.add(Production::new(3, |_, o| o.push(M::Fa))).unwrap();
    r.ignore([PLUS, MINUS]);
    let mut d = Derivation::new(
        r,
        signal_string("Fb[+Fa]Fa[-Fa]Fa[+Fa]Fa"),
        DeriveOptions::default(),
    );
    let expected = [
        "Fa[+Fb]Fb[-Fa]Fa[+Fa]Fa",
        "Fa[+Fa]Fa[-Fb]Fb[+Fa]Fa",
        "Fa[+Fa]Fa[-Fa]Fa[+Fb]Fb",
        "Fa[+Fa]Fa[-Fa]Fa[+Fa]Fa",
    ];
    for e in expected {
        d.step().unwrap();
        assert_eq!(d.string(), &signal_string(e));
    }
}

#[test]
fn right_context_with_brackets() {
    // A > [B]C : only the A whose next branch starts with B and is followed by C.
    let mut r = TypedRules::new();
    r.add(Production::new(A, |_, o| o.push(M::X(1.0))).right_pattern([
        ContextItem::Open,
        ContextItem::Module(B),
        ContextItem::Close,
        ContextItem::Module(X),
    ]))
    .unwrap();
    let axiom = vec![
        M::A,
        M::Open,
        M::B,
        M::A,
        M::Close,
        M::X(0.0),
        M::A,
        M::Open,
        M::A,
        M::Close,
        M::X(0.0),
    ];
    let mut d = Derivation::new(r, axiom, DeriveOptions::default());
    d.step().unwrap();
    assert_eq!(d.string()[0], M::X(1.0));
    assert_eq!(d.string()[3], M::A);
    assert_eq!(d.string()[6], M::A);
}

fn bush(seed: u64) -> Vec<M> {
    let mut r = TypedRules::new();
    r.add(
        Production::new(A, |_, o| o.extend([M::A, M::Open, M::Plus, M::A, M::Close]))
            .probability(1.0),
    )
    .unwrap();
    r.add(
        Production::new(A, |_, o| {
            o.extend([M::A, M::Open, M::Minus, M::A, M::Close])
        })
        .probability(1.0),
    )
    .unwrap();
    r.add(Production::new(A, |_, o| o.extend([M::F(1.0), M::A])).probability(2.0))
        .unwrap();
    r.add(Production::new(X, |_, o| {
        let v = o.random();
        o.push(M::X(v));
    }))
    .unwrap();
    let opts = DeriveOptions {
        seed,
        ..DeriveOptions::default()
    };
    let mut d = Derivation::new(r, vec![M::A, M::X(0.0)], opts);
    d.derive(8).unwrap();
    d.into_string()
}

#[test]
fn stochastic_derivation_is_reproducible_by_seed() {
    assert_eq!(bush(7), bush(7));
    assert_ne!(bush(7), bush(8));
    let s = bush(3);
    let pluses = s.iter().filter(|m| **m == M::Plus).count();
    let minuses = s.iter().filter(|m| **m == M::Minus).count();
    let fs = s.iter().filter(|m| matches!(m, M::F(_))).count();
    // Weights 1 : 1 : 2 over 8 steps of every A: all three productions were used.
    assert!(pluses > 0 && minuses > 0 && fs > 0);
}

#[test]
fn first_matching_production_wins_and_conditions_filter() {
    let mut r = TypedRules::new();
    r.add(
        Production::new(X, |m, o| {
            if let M::X(v) = m.module() {
                o.push(M::X(v + 1.0));
            }
        })
        .when(|m| matches!(m.module(), M::X(v) if *v < 3.0)),
    )
    .unwrap();
    r.add(Production::new(X, |_, _| {})).unwrap(); // x >= 3: erase
    let mut d = Derivation::new(
        r,
        vec![M::X(0.0), M::X(2.5), M::X(10.0)],
        DeriveOptions::default(),
    );
    d.step().unwrap();
    assert_eq!(d.string(), &vec![M::X(1.0), M::X(3.5)]);
    d.derive(3).unwrap();
    assert!(d.string().is_empty());
}

#[test]
fn cut_removes_rest_of_branch() {
    let axiom = vec![
        M::A,
        M::Open,
        M::B,
        M::Cut,
        M::A,
        M::Open,
        M::B,
        M::Close,
        M::B,
        M::Close,
        M::B,
        M::Cut,
        M::A,
    ];
    let mut d = Derivation::new(TypedRules::new(), axiom, DeriveOptions::default());
    let r = d.step().unwrap();
    assert_eq!(d.string(), &vec![M::A, M::Open, M::B, M::Close, M::B]);
    assert_eq!(r.cut, 8);
}

#[test]
fn decomposition_and_interpretation() {
    let mut r = TypedRules::new();
    r.add(Production::new(A, |_, o| o.extend([M::A, M::B])))
        .unwrap();
    // Decomposition: B → F(1) F(2) immediately, recursively: F(2) → F(1) F(1).
    r.add_decomposition(Production::new(B, |_, o| o.extend([M::F(1.0), M::F(2.0)])))
        .unwrap();
    r.add_decomposition(
        Production::new(F, |_, o| o.extend([M::F(1.0), M::F(1.0)]))
            .when(|m| matches!(m.module(), M::F(l) if *l > 1.5)),
    )
    .unwrap();
    // Interpretation: A draws a unit segment but stays an A in the string.
    r.add_interpretation(Production::new(A, |_, o| o.push(M::F(1.0))))
        .unwrap();
    let mut d = Derivation::new(r, vec![M::A], DeriveOptions::default());
    d.step().unwrap();
    assert_eq!(d.string(), &vec![M::A, M::F(1.0), M::F(1.0), M::F(1.0)]);
    let mut g = Geometry::default();
    let end = d.interpret(&mut g).unwrap();
    assert_eq!(g.segments.len(), 4);
    assert!((end.position.y - 4.0).abs() < 1e-12);
}

#[test]
fn guards_return_typed_errors() {
    let opts = DeriveOptions {
        max_len: 1000,
        max_steps: 40,
        ..DeriveOptions::default()
    };
    let mut d = Derivation::new(algae(), vec![M::B], opts);
    let e = d.derive(30).unwrap_err();
    assert!(
        matches!(e, LsystemError::StringTooLong { max: 1000, .. }),
        "{e}"
    );
    // The failed step left the last good string in place.
    assert_eq!(d.string().len(), 987);
    let mut d = Derivation::new(TypedRules::<M>::new(), vec![M::B], opts);
    assert!(matches!(
        d.derive(41),
        Err(LsystemError::TooManySteps {
            requested: 41,
            max: 40
        })
    ));
    let mut r = TypedRules::new();
    r.add_decomposition(Production::new(A, |_, o| o.push(M::A)))
        .unwrap();
    let mut d = Derivation::new(r, vec![M::A], opts);
    assert!(matches!(d.step(), Err(LsystemError::DepthExceeded { .. })));
    let mut r = TypedRules::<M>::new();
    assert!(
        r.add(Production::new(A, |_, _| {}).probability(f64::NAN))
            .is_err()
    );
}

struct Halver {
    calls: Vec<usize>,
}

impl Environment<Vec<M>> for Halver {
    fn communicate(&mut self, s: &mut Vec<M>, i: usize, t: &TurtleState) {
        self.calls.push(i);
        if let Some(M::E(v)) = s.get_mut(i) {
            *v = t.position.y + 0.5;
        }
    }
}

#[test]
fn queries_and_communication_between_steps() {
    // A → F(1) A ; the ?P and ?E modules are refreshed after every step.
    let mut r = TypedRules::new();
    r.add(Production::new(A, |_, o| o.extend([M::F(1.0), M::A])))
        .unwrap();
    let axiom = vec![M::A, M::P(-1.0, -1.0), M::E(0.0)];
    let mut d = Derivation::new(r, axiom, DeriveOptions::default());
    let mut env = Halver { calls: vec![] };
    let rep = d.derive_with(3, &mut env).unwrap();
    assert_eq!(rep.communicated, 1);
    assert_eq!(env.calls, vec![2, 3, 4, 5]); // axiom pass + 3 steps
    assert_eq!(d.string()[4], M::P(0.0, 3.0));
    assert_eq!(d.string()[5], M::E(3.5));
    let states = d.turtle_states().unwrap();
    assert_eq!(states[3].position.y, 3.0);
}

#[test]
fn closures_may_borrow_local_data() {
    let lengths = [3.0, 4.0];
    let mut r = TypedRules::new();
    r.add(Production::new(A, |_, o| {
        o.extend(lengths.iter().map(|&l| M::F(l)))
    }))
    .unwrap();
    let mut d = Derivation::new(&r, vec![M::A], DeriveOptions::default());
    d.step().unwrap();
    assert_eq!(d.string(), &vec![M::F(3.0), M::F(4.0)]);
}
