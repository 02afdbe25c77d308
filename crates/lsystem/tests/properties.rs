//! Property tests: parser robustness, printer round trip, identity grammars, determinism,
//! and the bracket-aware context matcher against a brute-force tree reference.
#![allow(clippy::unwrap_used)]

use polis_lsystem::context::{BranchIndex, ContextItem, ContextView, match_left, match_right};
use polis_lsystem::{DeriveOptions, Grammar, ModuleKind};
use proptest::prelude::*;

// ---- strategies ------------------------------------------------------------------

fn expr_text() -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        (0u32..1000).prop_map(|v| v.to_string()),
        (0u32..1000, 0u32..100).prop_map(|(a, b)| format!("{a}.{b}")),
        Just("x".to_string()),
        Just("y".to_string()),
        Just("k".to_string()),
        Just("pi".to_string()),
        Just("1e-3".to_string()),
    ];
    leaf.prop_recursive(4, 24, 3, |inner| {
        prop_oneof![
            (
                inner.clone(),
                prop::sample::select(vec![
                    "+", "-", "*", "/", "%", "^", "<", "<=", ">", ">=", "==", "!=", "&&", "||"
                ]),
                inner.clone()
            )
                .prop_map(|(a, o, b)| format!("{a} {o} {b}")),
            inner.clone().prop_map(|a| format!("({a})")),
            inner.clone().prop_map(|a| format!("-{a}")),
            inner.clone().prop_map(|a| format!("!({a})")),
            (inner.clone(), inner.clone(), inner.clone())
                .prop_map(|(c, a, b)| format!("({c} ? {a} : {b})")),
            (
                prop::sample::select(vec!["sin", "sqrt", "abs", "floor", "exp"]),
                inner.clone()
            )
                .prop_map(|(f, a)| format!("{f}({a})")),
            (inner.clone(), inner).prop_map(|(a, b)| format!("max({a}, {b})")),
        ]
    })
}

fn successor_text() -> impl Strategy<Value = String> {
    prop::collection::vec(
        prop_oneof![
            Just("F".to_string()),
            Just("+".to_string()),
            Just("[".to_string()),
            Just("]".to_string()),
            Just("%".to_string()),
            Just("?P(0,0)".to_string()),
            expr_text().prop_map(|e| format!("A({e})")),
            (expr_text(), expr_text()).prop_map(|(a, b)| format!("B({a}, {b})")),
        ],
        0..6,
    )
    .prop_map(|v| v.concat())
}

fn production_text() -> impl Strategy<Value = String> {
    (
        prop::option::of(Just("p1: ")),
        prop::sample::select(vec!["", "C < ", "C D < "]),
        prop::sample::select(vec!["A(x)", "B(x, y)"]),
        prop::sample::select(vec!["", " > D", " > [C]D", " > C ] D"]),
        prop::option::of(expr_text()),
        successor_text(),
        prop::option::of(0u32..5),
    )
        .prop_map(|(l, lc, pred, rc, cond, succ, prob)| {
            let pred = if pred == "A(x)"
                && (succ.contains('y') || cond.as_deref().is_some_and(|c| c.contains('y')))
            {
                "B(x, y)"
            } else {
                pred
            };
            let cond = cond.map_or(String::new(), |c| format!(" : {c}"));
            let prob = prob.map_or(String::new(), |p| format!(" : {p}"));
            format!("{}{lc}{pred}{rc}{cond} -> {succ}{prob}", l.unwrap_or(""))
        })
}

fn grammar_text() -> impl Strategy<Value = String> {
    (
        successor_text(),
        prop::collection::vec(production_text(), 0..5),
    )
        .prop_map(|(ax, ps)| format!("#define k 2.5\n#ignore +\nω: {ax}\n{}\n", ps.join("\n")))
}

fn module_string() -> impl Strategy<Value = String> {
    prop::collection::vec(
        prop_oneof![
            Just("A".to_string()),
            Just("B".to_string()),
            Just("C".to_string()),
            Just("+".to_string()),
            Just("-".to_string()),
            Just("[".to_string()),
            Just("]".to_string()),
            (0i32..10).prop_map(|v| format!("A({v})")),
            (0i32..10, 0i32..10).prop_map(|(a, b)| format!("B({a},{b})")),
        ],
        0..40,
    )
    .prop_map(|v| v.concat())
}

// ---- the parser never panics; printing round-trips -------------------------------

/// Case count of the parser properties: 256, or `LSYSTEM_PROPTEST_CASES` for a long run.
fn parser_cases() -> u32 {
    std::env::var("LSYSTEM_PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(256)
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: parser_cases(),
        max_global_rejects: parser_cases().saturating_mul(4),
        ..ProptestConfig::default()
    })]

    #[test]
    fn arbitrary_text_never_panics(s in ".{0,200}") {
        let _ = Grammar::parse(&s);
    }

    #[test]
    fn grammar_soup_never_panics(parts in prop::collection::vec(prop::sample::select(vec![
        "ω:", "#define", "#ignore", "#axiom", "#decomposition", "#interpretation", "#comm", "A", "B(x)",
        "(", ")", "<", ">", ":", "->", "→", "ε", "x", "1.5e", "1e999", "?", "?P", "@o", "[", "]", "%",
        "&&", "||", "!", "^", "/*", "*/", "//", "\n", ";", " ", ",", "p1:", "rand()", "-", "+",
        "#module Ab", "Ab", "Ab(x)", "#module",
    ]), 0..40)) {
        let s = parts.concat();
        if let Ok(g) = Grammar::parse(&s) {
            // Whatever parses also derives without panicking.
            let mut d = g.derivation(DeriveOptions { max_len: 10_000, ..DeriveOptions::default() });
            let _ = d.derive(3);
            let _ = Grammar::parse(&g.to_text()).unwrap();
        }
    }

    #[test]
    fn parse_print_parse_is_stable(text in grammar_text()) {
        let g = Grammar::parse(&text);
        prop_assume!(g.is_ok());
        let g = g.unwrap();
        let printed = g.to_text();
        let g2 = Grammar::parse(&printed).unwrap_or_else(|e| panic!("{e}\n{printed}"));
        prop_assert_eq!(g.ast(), g2.ast());
        prop_assert_eq!(g2.to_text(), printed);
    }

    #[test]
    fn identity_grammar_leaves_any_string_unchanged(axiom in module_string(), seed in any::<u64>()) {
        let src = format!(
            "#ignore + -\nω: {axiom}\nA(x) -> A(x)\nB(x,y) : x > y -> B(x,y)\nB < C -> C\nC > [A] -> C : 1\nC -> C : 3\nA -> A"
        );
        let g = Grammar::parse(&src).unwrap();
        let mut d = g.derivation(DeriveOptions { seed, ..DeriveOptions::default() });
        d.derive(3).unwrap();
        prop_assert_eq!(d.string(), g.axiom());
    }

    #[test]
    fn derivation_is_deterministic_per_seed(text in grammar_text(), seed in any::<u64>()) {
        let g = Grammar::parse(&text);
        prop_assume!(g.is_ok());
        let g = g.unwrap();
        let opts = DeriveOptions { seed, max_len: 20_000, ..DeriveOptions::default() };
        let run = || {
            let mut d = g.derivation(opts);
            let r = d.derive(4).map(|_| ());
            (r, g.format_string(d.string()))
        };
        prop_assert_eq!(run(), run());
    }
}

// ---- context matching against a brute-force reference -----------------------------

struct Chars(Vec<char>, Vec<char>);

impl ContextView for Chars {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn kind(&self, i: usize) -> ModuleKind {
        match self.0[i] {
            '[' => ModuleKind::BranchOpen,
            ']' => ModuleKind::BranchClose,
            _ => ModuleKind::Plain,
        }
    }
    fn ignored(&self, i: usize) -> bool {
        self.1.contains(&self.0[i])
    }
}

/// The string as an explicit tree: lists of items, each a module position or a sub-branch.
#[derive(Clone, Copy)]
enum Item {
    M(usize),
    Br(usize),
}

struct Tree {
    lists: Vec<Vec<Item>>,
    parent: Vec<Option<(usize, usize)>>,
    at: Vec<(usize, usize)>,
}

fn tree(s: &[char]) -> Tree {
    let mut t = Tree {
        lists: vec![vec![]],
        parent: vec![None],
        at: vec![(0, 0); s.len()],
    };
    let mut cur = 0;
    for (p, &c) in s.iter().enumerate() {
        match c {
            '[' => {
                let id = t.lists.len();
                let idx = t.lists[cur].len();
                t.lists[cur].push(Item::Br(id));
                t.lists.push(vec![]);
                t.parent.push(Some((cur, idx)));
                cur = id;
            }
            ']' => cur = t.parent[cur].unwrap().0,
            _ => {
                t.at[p] = (cur, t.lists[cur].len());
                t.lists[cur].push(Item::M(p));
            }
        }
    }
    t
}

fn ref_left(t: &Tree, s: &Chars, p: usize, pat: &[char]) -> bool {
    let (mut list, mut idx) = t.at[p];
    for &want in pat.iter().rev() {
        loop {
            if idx == 0 {
                match t.parent[list] {
                    None => return false,
                    Some((pl, pi)) => {
                        list = pl;
                        idx = pi;
                        continue;
                    }
                }
            }
            idx -= 1;
            match t.lists[list][idx] {
                Item::Br(_) => continue,
                Item::M(q) if s.1.contains(&s.0[q]) => continue,
                Item::M(q) => {
                    if s.0[q] == want {
                        break;
                    }
                    return false;
                }
            }
        }
    }
    true
}

fn ref_right(t: &Tree, s: &Chars, p: usize, pat: &[char]) -> bool {
    let (mut list, mut idx) = t.at[p];
    idx += 1;
    for &want in pat {
        match want {
            '[' => loop {
                match t.lists[list].get(idx) {
                    None => return false,
                    Some(Item::M(q)) if s.1.contains(&s.0[*q]) => idx += 1,
                    Some(Item::M(_)) => return false,
                    Some(Item::Br(b)) => {
                        list = *b;
                        idx = 0;
                        break;
                    }
                }
            },
            ']' => match t.parent[list] {
                None => return false,
                Some((pl, pi)) => {
                    list = pl;
                    idx = pi + 1;
                }
            },
            _ => loop {
                match t.lists[list].get(idx) {
                    None => return false,
                    Some(Item::Br(_)) => idx += 1,
                    Some(Item::M(q)) if s.1.contains(&s.0[*q]) => idx += 1,
                    Some(Item::M(q)) => {
                        if s.0[*q] == want {
                            idx += 1;
                            break;
                        }
                        return false;
                    }
                }
            },
        }
    }
    true
}

fn balanced(raw: Vec<char>) -> Vec<char> {
    let mut out = Vec::new();
    let mut depth = 0usize;
    for c in raw {
        match c {
            '[' => depth += 1,
            ']' if depth == 0 => continue,
            ']' => depth -= 1,
            _ => {}
        }
        out.push(c);
    }
    out.extend(std::iter::repeat_n(']', depth));
    out
}

fn item(c: char) -> ContextItem<char> {
    match c {
        '[' => ContextItem::Open,
        ']' => ContextItem::Close,
        c => ContextItem::Module(c),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn context_matches_brute_force_reference(
        raw in prop::collection::vec(prop::sample::select(vec!['A', 'B', 'C', '+', '[', '[', ']', ']']), 0..30),
        left in prop::collection::vec(prop::sample::select(vec!['A', 'B', 'C']), 0..3),
        right in prop::collection::vec(prop::sample::select(vec!['A', 'B', 'C', '[', ']']), 0..4),
        ignore_plus in any::<bool>(),
        ignore_c in any::<bool>(),
    ) {
        let s = balanced(raw);
        let mut ign = Vec::new();
        if ignore_plus { ign.push('+'); }
        if ignore_c { ign.push('C'); }
        let view = Chars(s.clone(), ign);
        let mut branches = BranchIndex::default();
        branches.rebuild(view.len(), |i| view.kind(i));
        let t = tree(&s);
        let lp: Vec<_> = left.iter().map(|&c| item(c)).collect();
        let rp: Vec<_> = right.iter().map(|&c| item(c)).collect();
        let mut out = Vec::new();
        for p in 0..s.len() {
            if matches!(s[p], '[' | ']') {
                continue;
            }
            let eng_l = match_left(&view, &branches, p, &lp, |&c, q| view.0[q] == c, &mut out);
            prop_assert_eq!(eng_l, ref_left(&t, &view, p, &left), "left {:?} at {} in {}", left, p, s.iter().collect::<String>());
            if eng_l {
                prop_assert_eq!(out.len(), left.len());
            }
            let eng_r = match_right(&view, &branches, p, &rp, |&c, q| view.0[q] == c, &mut out);
            prop_assert_eq!(eng_r, ref_right(&t, &view, p, &right), "right {:?} at {} in {}", right, p, s.iter().collect::<String>());
        }
    }
}
