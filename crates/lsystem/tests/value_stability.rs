//! Value stability: the exact strings (symbols and parameter bits) derived from the peer
//! grammars G1–C2 (`PEERS.md`, smaller sizes) and from a bracketed context-sensitive
//! grammar with an ignore set, pinned as digests. The digests were taken with the engine
//! before its fast paths (successor arguments of the simple shapes and `a op b` pairs
//! evaluated without bytecode, neighbour contexts on bracket-free strings, buffers sized
//! from the last step's growth), so they prove those fast paths change no bit.
#![allow(clippy::unwrap_used)]

use polis_lsystem::{DeriveOptions, Grammar, ParamString};

/// FNV-1a over symbol ids, parameter counts and parameter bits.
fn digest(s: &ParamString) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |v: u64| {
        for b in v.to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for (sym, params) in s.iter() {
        eat(u64::from(sym));
        eat(params.len() as u64);
        for p in params {
            eat(p.to_bits());
        }
    }
    h
}

fn derive(text: &str, steps: usize, seed: u64) -> (usize, u64) {
    let g = Grammar::parse(text).unwrap();
    let mut d = g.derivation(DeriveOptions {
        seed,
        ..DeriveOptions::default()
    });
    d.derive(steps).unwrap();
    (d.string().len(), digest(d.string()))
}

#[test]
fn g1_parametric_doubling() {
    let got = derive(
        "ω: A(1)\nA(x) -> A(x+1) B(x*0.5)\nB(x) -> A(x-1) B(x*0.5)",
        12,
        0,
    );
    assert_eq!(got, (4096, 0x5b01_23f9_03dd_44ed), "{got:x?}");
}

#[test]
fn g2_stochastic() {
    let got = derive(
        "ω: A(1)\nA(x) -> A(x+1) B(x*0.5) : 0.5\nA(x) -> B(x*0.5) A(x+1) : 0.5\n\
         B(x) -> A(x-1) B(x*0.5)",
        12,
        42,
    );
    assert_eq!(got, (4096, 0xf889_8a0f_45e8_4079), "{got:x?}");
}

#[test]
fn g3_branching() {
    let got = derive(
        "ω: A(1)\nA(l) -> F(l) [ +(30) A(l*0.7) ] [ -(30) A(l*0.7) ]",
        9,
        0,
    );
    assert_eq!(got, (4089, 0x7e60_b9a4_0b94_c381), "{got:x?}");
}

#[test]
fn c1_context_subdivision() {
    let got = derive(
        "ω: L A(0) R\n\
         A(x) < A(y) > A(z) -> A(0.25*x+0.75*y) A(0.75*y+0.25*z)\n\
         L < A(y) > A(z) -> A(y) A(0.75*y+0.25*z)\n\
         A(x) < A(y) > R -> A(0.25*x+0.75*y) A(y)\n\
         L < A(y) > R -> A(y) A(y+1)",
        12,
        0,
    );
    assert_eq!(got, (4098, 0x5259_49ac_ab9d_fc50), "{got:x?}");
}

#[test]
fn c2_signal() {
    let axiom = "A(1) B(2) C(3) ".repeat(500);
    let got = derive(
        &format!("ω: {axiom} B(1) A(2)\nA(x) < B(y) > C(z) -> B(x+y+z)"),
        2,
        0,
    );
    assert_eq!(got, (1502, 0xe912_dea7_8557_11a5), "{got:x?}");
}

#[test]
fn bracketed_context_with_ignore() {
    // Acropetal signal over a branching structure: left contexts walk across `[`, skip
    // sibling branches and the ignored turns; the fast neighbour path must not apply.
    let got = derive(
        "#ignore + -\nω: I(1) [ + I(0) I(0) ] [ - I(0) [ + I(0) ] I(0) ] I(0) I(0)\n\
         I(s) < I(t) -> I(max(s,t) + 0.5*t)\n\
         I(t) : t > 0.75 -> I(t) [ + I(0) ] I(t*0.25)",
        14,
        0,
    );
    assert_eq!(got, (87, 0x24a3_8c14_8bd5_ae6e), "{got:x?}");
}
