//! Derivation throughput (modules produced per second) of polis-lsystem, single thread,
//! on strings of about 10⁶ modules:
//!
//! * `context_free_*`: a parametric branching plant
//!   `A(l,w) : w < 1000 -> F(l)[+A(l*0.6,w+1)]A(l*0.9,w+1)`, `F(l) -> F(l*1.05)`;
//! * `context_sensitive_*`: parametric acropetal signal propagation
//!   `I(s) < I(t) -> I(max(s,t))` with `#ignore + -` over a ternary branching structure;
//!
//! each through the text grammar (`text_*`) and typed modules with closures (`typed_*`).
//! One sample = one derivation step from the prepared string; the counter is the number of
//! modules in the produced string. Working memory (buffer capacities) and the process's
//! peak resident set are printed before the divan table.
//!
//! Run: `cargo bench -p polis-lsystem --bench lsystem`

use std::sync::LazyLock;

use divan::Bencher;
use divan::counter::ItemsCount;
use polis_lsystem::{
    Command, Derivation, DeriveOptions, Grammar, Module, ParamString, Production, TypedRules,
};

fn main() {
    report_memory();
    report_cpu_time();
    divan::main();
}

/// On-CPU time of this thread in nanoseconds (Linux `schedstat`), if available.
fn cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Throughput per second of on-CPU time: on a shared, loaded machine wall-clock samples
/// include time spent waiting for a core; this does not.
fn report_cpu_time() {
    const RUNS: u32 = 10;
    fn measure(name: &str, mut step: impl FnMut() -> usize) {
        let _ = step(); // warm buffers
        let (Some(t0), w0) = (cpu_ns(), std::time::Instant::now()) else {
            return;
        };
        let mut produced = 0usize;
        for _ in 0..RUNS {
            produced += step();
        }
        let Some(t1) = cpu_ns() else { return };
        let cpu = (t1 - t0) as f64 * 1e-9;
        let wall = w0.elapsed().as_secs_f64();
        println!(
            "  {name:<24} {:>7.1} M modules per CPU-second ({:>5.1} ms CPU, {:>5.1} ms wall per step)",
            produced as f64 / cpu / 1e6,
            cpu * 1e3 / f64::from(RUNS),
            wall * 1e3 / f64::from(RUNS)
        );
    }
    println!("polis-lsystem throughput per on-CPU second ({RUNS} steps each):");
    let (g, s) = &*CF;
    let mut d = Derivation::new(g, s.clone(), opts());
    measure("context_free_text", || {
        d.restart(s);
        d.step().map(|r| r.len).unwrap_or(0)
    });
    let rules = typed_cf_rules();
    let mut d = Derivation::new(&rules, TYPED_CF.clone(), opts());
    measure("context_free_typed", || {
        d.restart(&TYPED_CF);
        d.step().map(|r| r.len).unwrap_or(0)
    });
    let (g, s) = &*CS;
    let mut d = Derivation::new(g, s.clone(), opts());
    measure("context_sensitive_text", || {
        d.step().map(|r| r.len).unwrap_or(0)
    });
    let rules = typed_cs_rules();
    let mut d = Derivation::new(&rules, TYPED_CS.clone(), opts());
    measure("context_sensitive_typed", || {
        d.step().map(|r| r.len).unwrap_or(0)
    });
}

const CF_TEXT: &str = "
    ω: A(1,0)
    A(l,w) : w < 1000 -> F(l)[+A(l*0.6,w+1)]A(l*0.9,w+1)
    F(l) -> F(l*1.05)
";

const CS_TEXT: &str = "
    #ignore + -
    ω: I(1)X
    #decomposition
    #productions
    I(s) < I(t) -> I(max(s,t))
";

const GEN_TEXT: &str = "ω: I(1)X\nX -> I(0)[+X][-X]I(0)X";

fn opts() -> DeriveOptions {
    DeriveOptions::default()
}

/// Derives `text` until the string has at least `target` modules; returns the grammar and string.
fn grow(text: &str, target: usize) -> (Grammar, ParamString) {
    let g = Grammar::parse(text).unwrap_or_else(|e| panic!("{e}"));
    let mut d = g.derivation(opts());
    while d.string().len() < target {
        d.step().unwrap_or_else(|e| panic!("{e}"));
    }
    let s = d.string().clone();
    (g, s)
}

static CF: LazyLock<(Grammar, ParamString)> = LazyLock::new(|| grow(CF_TEXT, 1_000_000));

static CS: LazyLock<(Grammar, ParamString)> = LazyLock::new(|| {
    let (_, s) = grow(GEN_TEXT, 800_000);
    let g = Grammar::parse(CS_TEXT).unwrap_or_else(|e| panic!("{e}"));
    // Same symbols in both grammars? Re-encode through text to be safe.
    let gen_g = Grammar::parse(GEN_TEXT).unwrap_or_else(|e| panic!("{e}"));
    let s = g
        .parse_string(&gen_g.format_string(&s))
        .unwrap_or_else(|e| panic!("{e}"));
    (g, s)
});

// ---- typed modules -----------------------------------------------------------------

#[derive(Clone, Copy, Debug, PartialEq)]
enum T {
    A(f64, f64),
    F(f64),
    Open,
    Close,
    Plus,
}

const SYM_A: u32 = 0;
const SYM_F: u32 = 1;
const SYM_I: u32 = 2;
const SYM_X: u32 = 3;
const SYM_PLUS: u32 = 6;
const SYM_MINUS: u32 = 7;

impl Module for T {
    #[inline]
    fn symbol(&self) -> u32 {
        match self {
            T::A(..) => SYM_A,
            T::F(_) => SYM_F,
            T::Open => 4,
            T::Close => 5,
            T::Plus => SYM_PLUS,
        }
    }
    #[inline]
    fn command(&self) -> Command {
        match self {
            T::F(l) => Command::Forward(Some(*l)),
            T::Open => Command::Push,
            T::Close => Command::Pop,
            T::Plus => Command::TurnLeft(None),
            _ => Command::None,
        }
    }
}

fn typed_cf_rules() -> TypedRules<'static, T> {
    let mut r = TypedRules::new();
    r.add(
        Production::new(SYM_A, |m, o| {
            if let T::A(l, w) = *m.module() {
                o.extend([
                    T::F(l),
                    T::Open,
                    T::Plus,
                    T::A(l * 0.6, w + 1.0),
                    T::Close,
                    T::A(l * 0.9, w + 1.0),
                ]);
            }
        })
        .when(|m| matches!(m.module(), T::A(_, w) if *w < 1000.0)),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    r.add(Production::new(SYM_F, |m, o| {
        if let T::F(l) = *m.module() {
            o.push(T::F(l * 1.05));
        }
    }))
    .unwrap_or_else(|e| panic!("{e}"));
    r
}

/// The modules of the context-sensitive system (16 bytes each).
#[derive(Clone, Copy, Debug, PartialEq)]
enum S {
    I(f64),
    X,
    Open,
    Close,
    Plus,
    Minus,
}

impl Module for S {
    #[inline]
    fn symbol(&self) -> u32 {
        match self {
            S::I(_) => SYM_I,
            S::X => SYM_X,
            S::Open => 4,
            S::Close => 5,
            S::Plus => SYM_PLUS,
            S::Minus => SYM_MINUS,
        }
    }
    #[inline]
    fn command(&self) -> Command {
        match self {
            S::Open => Command::Push,
            S::Close => Command::Pop,
            S::Plus => Command::TurnLeft(None),
            S::Minus => Command::TurnRight(None),
            _ => Command::None,
        }
    }
}

fn typed_cs_rules() -> TypedRules<'static, S> {
    let mut r = TypedRules::new();
    r.add(
        Production::new(SYM_I, |m, o| {
            if let (Some(S::I(s)), S::I(t)) = (m.left(0), m.module()) {
                o.push(S::I(s.max(*t)));
            }
        })
        .left([SYM_I]),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    r.ignore([SYM_PLUS, SYM_MINUS]);
    r
}

fn typed_grow<M: Module>(rules: &TypedRules<'_, M>, axiom: Vec<M>, target: usize) -> Vec<M> {
    let mut d = Derivation::new(rules, axiom, opts());
    while d.string().len() < target {
        d.step().unwrap_or_else(|e| panic!("{e}"));
    }
    d.into_string()
}

static TYPED_CF: LazyLock<Vec<T>> =
    LazyLock::new(|| typed_grow(&typed_cf_rules(), vec![T::A(1.0, 0.0)], 1_000_000));

static TYPED_CS: LazyLock<Vec<S>> = LazyLock::new(|| {
    let mut g = TypedRules::new();
    g.add(Production::new(SYM_X, |_, o| {
        o.extend([
            S::I(0.0),
            S::Open,
            S::Plus,
            S::X,
            S::Close,
            S::Open,
            S::Minus,
            S::X,
            S::Close,
            S::I(0.0),
            S::X,
        ]);
    }))
    .unwrap_or_else(|e| panic!("{e}"));
    typed_grow(&g, vec![S::I(1.0), S::X], 800_000)
});

// ---- benchmarks --------------------------------------------------------------------

/// One sample: `restart` from the prepared string (a copy into the kept buffer, timed)
/// and one step. Buffers are warm after the first sample, as in a long derivation.
fn text_step(b: Bencher<'_, '_>, data: &(Grammar, ParamString)) {
    let (g, s) = data;
    let mut d = Derivation::new(g, s.clone(), opts());
    let out = d.step().map(|r| r.len).unwrap_or(0);
    b.counter(ItemsCount::new(out)).bench_local(|| {
        d.restart(s);
        d.step().map(|r| r.len)
    });
}

fn typed_step(b: Bencher<'_, '_>, rules: &TypedRules<'_, T>, s: &Vec<T>) {
    let mut d = Derivation::new(rules, s.clone(), opts());
    let out = d.step().map(|r| r.len).unwrap_or(0);
    b.counter(ItemsCount::new(out)).bench_local(|| {
        d.restart(s);
        d.step().map(|r| r.len)
    });
}

#[divan::bench(sample_count = 20, sample_size = 1)]
fn context_free_text(b: Bencher<'_, '_>) {
    text_step(b, &CF);
}

#[divan::bench(sample_count = 20, sample_size = 1)]
fn context_free_typed(b: Bencher<'_, '_>) {
    let r = typed_cf_rules();
    typed_step(b, &r, &TYPED_CF);
}

/// One sample: one more step of a derivation whose length does not change (the signal
/// keeps propagating), so buffers are warm and nothing is copied.
#[divan::bench(sample_count = 20, sample_size = 1)]
fn context_sensitive_text(b: Bencher<'_, '_>) {
    let (g, s) = &*CS;
    let mut d = Derivation::new(g, s.clone(), opts());
    let out = d.step().map(|r| r.len).unwrap_or(0);
    b.counter(ItemsCount::new(out))
        .bench_local(|| d.step().map(|r| r.len));
}

#[divan::bench(sample_count = 20, sample_size = 1)]
fn context_sensitive_typed(b: Bencher<'_, '_>) {
    let r = typed_cs_rules();
    let mut d = Derivation::new(&r, TYPED_CS.clone(), opts());
    let out = d.step().map(|r| r.len).unwrap_or(0);
    b.counter(ItemsCount::new(out))
        .bench_local(|| d.step().map(|r| r.len));
}

/// Prints the working memory of one step of each system and the process's peak RSS.
fn report_memory() {
    println!("polis-lsystem working memory after one step from the benchmark strings:");
    let (g, s) = &*CF;
    let mut d = Derivation::new(g, s.clone(), opts());
    let r = d.step().map(|r| r.len).unwrap_or(0);
    println!(
        "  context_free_text       in {:>9} out {:>9} modules, buffers {:>6.1} MiB ({:.1} B/module)",
        s.len(),
        r,
        d.heap_bytes() as f64 / 1048576.0,
        d.heap_bytes() as f64 / r.max(1) as f64
    );
    let (g, s) = &*CS;
    let mut d = Derivation::new(g, s.clone(), opts());
    let r = d.step().map(|r| r.len).unwrap_or(0);
    println!(
        "  context_sensitive_text  in {:>9} out {:>9} modules, buffers {:>6.1} MiB ({:.1} B/module)",
        s.len(),
        r,
        d.heap_bytes() as f64 / 1048576.0,
        d.heap_bytes() as f64 / r.max(1) as f64
    );
    let rules = typed_cf_rules();
    let mut d = Derivation::new(&rules, TYPED_CF.clone(), opts());
    let r = d.step().map(|r| r.len).unwrap_or(0);
    println!(
        "  context_free_typed      in {:>9} out {:>9} modules, buffers {:>6.1} MiB ({:.1} B/module)",
        TYPED_CF.len(),
        r,
        d.heap_bytes() as f64 / 1048576.0,
        d.heap_bytes() as f64 / r.max(1) as f64
    );
    let rules = typed_cs_rules();
    let mut d = Derivation::new(&rules, TYPED_CS.clone(), opts());
    let r = d.step().map(|r| r.len).unwrap_or(0);
    println!(
        "  context_sensitive_typed in {:>9} out {:>9} modules, buffers {:>6.1} MiB ({:.1} B/module)",
        TYPED_CS.len(),
        r,
        d.heap_bytes() as f64 / 1048576.0,
        d.heap_bytes() as f64 / r.max(1) as f64
    );
    if let Ok(status) = std::fs::read_to_string("/proc/self/status") {
        for line in status
            .lines()
            .filter(|l| l.starts_with("VmHWM") || l.starts_with("VmRSS"))
        {
            println!("  {line}");
        }
    }
}
