//! polis-lsystem against symbios 1.5.1 on the five grammars of the peer table
//! (G1, G2, G3, C1, C2): a fresh derivation per run, only the derivation timed, the two
//! engines interleaved run by run (A B A B) so both see the same machine load.
//!
//! Reports modules *written* per second (the sum of the string lengths after every step)
//! for both engines, by wall time and by the thread's on-CPU time
//! (`/proc/thread-self/schedstat`), and the ratio polis / symbios of the medians.
//!
//! Run: `cargo run --release --manifest-path benches/lsystem-symbios/Cargo.toml -- [passes] [grammar…]`
//! (default 5 passes, every grammar).

use std::hint::black_box;
use std::time::Instant;

use polis_lsystem::{DeriveOptions, Grammar};

/// One workload: the rules in both notations, the axiom, the number of steps.
struct Workload {
    id: &'static str,
    /// symbios rules, one per `add_rule`.
    symbios_rules: &'static [&'static str],
    /// The same rules in polis's text grammar (probability after the successor).
    polis_rules: &'static str,
    axiom: String,
    steps: usize,
    seed: Option<u64>,
}

fn workloads() -> Vec<Workload> {
    vec![
        Workload {
            id: "G1",
            symbios_rules: &["A(x) -> A(x+1) B(x*0.5)", "B(x) -> A(x-1) B(x*0.5)"],
            polis_rules: "A(x) -> A(x+1) B(x*0.5)\nB(x) -> A(x-1) B(x*0.5)",
            axiom: "A(1)".into(),
            steps: 20,
            seed: None,
        },
        Workload {
            id: "G2",
            symbios_rules: &[
                "0.5: A(x) -> A(x+1) B(x*0.5)",
                "0.5: A(x) -> B(x*0.5) A(x+1)",
                "B(x) -> A(x-1) B(x*0.5)",
            ],
            polis_rules: "A(x) -> A(x+1) B(x*0.5) : 0.5\nA(x) -> B(x*0.5) A(x+1) : 0.5\nB(x) -> A(x-1) B(x*0.5)",
            axiom: "A(1)".into(),
            steps: 20,
            seed: Some(42),
        },
        Workload {
            id: "G3",
            symbios_rules: &["A(l) -> F(l) [ +(30) A(l*0.7) ] [ -(30) A(l*0.7) ]"],
            polis_rules: "A(l) -> F(l) [ +(30) A(l*0.7) ] [ -(30) A(l*0.7) ]",
            axiom: "A(1)".into(),
            steps: 17,
            seed: None,
        },
        Workload {
            id: "C1",
            symbios_rules: &[
                "A(x) < A(y) > A(z) -> A(0.25*x+0.75*y) A(0.75*y+0.25*z)",
                "L < A(y) > A(z) -> A(y) A(0.75*y+0.25*z)",
                "A(x) < A(y) > R -> A(0.25*x+0.75*y) A(y)",
                "L < A(y) > R -> A(y) A(y+1)",
            ],
            polis_rules: "A(x) < A(y) > A(z) -> A(0.25*x+0.75*y) A(0.75*y+0.25*z)\n\
                          L < A(y) > A(z) -> A(y) A(0.75*y+0.25*z)\n\
                          A(x) < A(y) > R -> A(0.25*x+0.75*y) A(y)\n\
                          L < A(y) > R -> A(y) A(y+1)",
            axiom: "L A(0) R".into(),
            steps: 20,
            seed: None,
        },
        Workload {
            id: "C2",
            symbios_rules: &["A(x) < B(y) > C(z) -> B(x+y+z)"],
            polis_rules: "A(x) < B(y) > C(z) -> B(x+y+z)",
            axiom: "A(1) B(1) C(1) ".repeat(333_334).trim_end().to_string(),
            steps: 1,
            seed: None,
        },
    ]
}

/// On-CPU time of this thread in nanoseconds (Linux), if available.
fn cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Wall and CPU seconds of one timed closure.
fn timed(f: impl FnOnce()) -> (f64, f64) {
    let c0 = cpu_ns();
    let w0 = Instant::now();
    f();
    let wall = w0.elapsed().as_secs_f64();
    let cpu = match (c0, cpu_ns()) {
        (Some(a), Some(b)) => (b.saturating_sub(a)) as f64 * 1e-9,
        _ => f64::NAN,
    };
    (wall, cpu)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// A fresh symbios system with the workload's rules and axiom (not timed).
fn symbios_system(w: &Workload) -> symbios::System {
    let mut sys = symbios::System::new();
    sys.max_capacity = 8_000_000;
    sys.state.max_capacity = 8_000_000;
    if let Some(seed) = w.seed {
        sys.set_seed(seed);
    }
    for r in w.symbios_rules {
        if let Err(e) = sys.add_rule(r) {
            panic!("symbios rejected {r:?}: {e:?}");
        }
    }
    if let Err(e) = sys.set_axiom(&w.axiom) {
        panic!("symbios rejected the axiom of {}: {e:?}", w.id);
    }
    sys
}

fn polis_grammar(w: &Workload) -> Grammar {
    let text = format!("ω: {}\n{}", w.axiom, w.polis_rules);
    match Grammar::parse(&text) {
        Ok(g) => g,
        Err(e) => panic!("polis rejected {}: {e}", w.id),
    }
}

fn polis_options(w: &Workload) -> DeriveOptions {
    DeriveOptions {
        seed: w.seed.unwrap_or(0),
        ..DeriveOptions::default()
    }
}

/// Modules written by a derivation (sum of the lengths after every step) and the final
/// length, from polis (the two engines derive strings of the same lengths; checked).
fn written(w: &Workload, g: &Grammar) -> (usize, usize) {
    let mut d = g.derivation(polis_options(w));
    let mut sum = 0;
    let mut last = 0;
    for _ in 0..w.steps {
        match d.step() {
            Ok(r) => {
                sum += r.len;
                last = r.len;
            }
            Err(e) => panic!("polis failed on {}: {e}", w.id),
        }
    }
    (sum, last)
}

fn main() {
    let mut args = std::env::args().skip(1).peekable();
    if args.peek().map(String::as_str) == Some("polis") {
        // One polis derivation per named grammar, nothing else: for profilers
        // (`valgrind --tool=callgrind … -- polis C2`).
        let only: Vec<String> = args.skip(1).collect();
        for w in workloads() {
            if only.is_empty() || only.iter().any(|o| o == w.id) {
                let g = polis_grammar(&w);
                let mut d = g.derivation(polis_options(&w));
                if let Err(e) = d.derive(w.steps) {
                    panic!("polis failed on {}: {e}", w.id);
                }
                println!("{} {}", w.id, d.string().len());
            }
        }
        return;
    }
    let passes: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(5);
    let only: Vec<String> = args.collect();
    sanity();
    println!(
        "polis-lsystem vs symbios 1.5.1, fresh derivation, {passes} interleaved passes, medians"
    );
    println!(
        "{:<4} {:>10} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9}",
        "id", "written", "polis ms", "symb. ms", "polis M/s", "symb. M/s", "wall ×", "CPU ×"
    );
    for w in workloads() {
        if !only.is_empty() && !only.iter().any(|o| o == w.id) {
            continue;
        }
        let g = polis_grammar(&w);
        let (total, final_len) = written(&w, &g);
        {
            let mut sys = symbios_system(&w);
            if let Err(e) = sys.derive(w.steps) {
                panic!("symbios failed on {}: {e:?}", w.id);
            }
            assert_eq!(sys.state.len(), final_len, "{}: final lengths differ", w.id);
        }
        let (mut pw, mut pc, mut sw, mut sc) = (vec![], vec![], vec![], vec![]);
        for _ in 0..passes {
            let mut d = g.derivation(polis_options(&w));
            let (wall, cpu) = timed(|| {
                if let Err(e) = d.derive(w.steps) {
                    panic!("polis failed on {}: {e}", w.id);
                }
            });
            black_box(d.string().len());
            drop(d);
            pw.push(wall);
            pc.push(cpu);
            let mut sys = symbios_system(&w);
            let (wall, cpu) = timed(|| {
                if let Err(e) = sys.derive(w.steps) {
                    panic!("symbios failed on {}: {e:?}", w.id);
                }
            });
            black_box(sys.state.len());
            drop(sys);
            sw.push(wall);
            sc.push(cpu);
        }
        let (pw, pc, sw, sc) = (
            median(&mut pw),
            median(&mut pc),
            median(&mut sw),
            median(&mut sc),
        );
        let t = total as f64;
        println!(
            "{:<4} {:>10} {:>10.1} {:>10.1} {:>10.1} {:>10.1} {:>8.2}× {:>8.2}×",
            w.id,
            total,
            pw * 1e3,
            sw * 1e3,
            t / pw / 1e6,
            t / sw / 1e6,
            sw / pw,
            sc / pc
        );
    }
}

/// The sanity strings of the peer table, so both engines are known to derive the same
/// language.
fn sanity() {
    let ws = workloads();
    for (id, steps, want) in [
        (
            "G1",
            3,
            "A(4) B(1.5) A(0) B(0.5) A(0.5) B(-0.25) A(-0.75) B(0.125)",
        ),
        (
            "C1",
            3,
            "L A(0) A(0.0625) A(0.1875) A(0.375) A(0.625) A(0.8125) A(0.9375) A(1) R",
        ),
    ] {
        let Some(w) = ws.iter().find(|w| w.id == id) else {
            continue;
        };
        let g = polis_grammar(w);
        let mut d = g.derivation(polis_options(w));
        if let Err(e) = d.derive(steps) {
            panic!("polis failed on {id}: {e}");
        }
        let got = g.format_string(d.string());
        let norm = |s: &str| s.replace(' ', "");
        assert_eq!(norm(&got), norm(want), "{id} after {steps} steps");
    }
}
