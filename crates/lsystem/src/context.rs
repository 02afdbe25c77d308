//! Bracket-aware context matching (ABOP §1.8, as in cpfg).
//!
//! * The **left context** follows the path toward the root: walking left from the
//!   predecessor, a `[` is stepped over (we are entering the parent branch), and a
//!   complete bracketed sibling `[ … ]` is skipped as a whole.
//! * The **right context** continues along the current branch: a bracketed branch that
//!   the pattern does not mention is skipped as a whole, the end of the current branch
//!   (`]`) ends the match. A right-context pattern may itself contain brackets: `[` must
//!   meet a `[`, and `]` skips the rest of the current branch (so `S > G[H]M` matches
//!   `S G[H I[J K]L]M`).
//! * Modules in the ignore set are skipped by both walks wherever they appear.
//!
//! Both walks are linear in the number of modules they visit; bracket partners come from
//! a [`BranchIndex`] built once per derivation step.

use crate::command::ModuleKind;

/// One element of a context pattern.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum ContextItem<T> {
    /// A module, described by `T` (a symbol id for typed modules).
    Module(T),
    /// `[` (right context only).
    Open,
    /// `]` (right context only): skip the rest of the current branch.
    Close,
}

const NONE: u32 = u32::MAX;

/// Partner positions of the brackets of a string, built in one pass.
#[derive(Debug, Clone, Default)]
pub struct BranchIndex {
    partner: Vec<u32>,
    stack: Vec<u32>,
    bracket_free: bool,
}

impl BranchIndex {
    /// Rebuilds the index for a string of `n` modules whose kinds `kind(i)` reports.
    /// Unbalanced brackets get no partner (and then never match a context).
    pub fn rebuild(&mut self, n: usize, mut kind: impl FnMut(usize) -> ModuleKind) {
        self.partner.clear();
        self.partner.resize(n, NONE);
        self.stack.clear();
        self.bracket_free = true;
        for i in 0..n {
            match kind(i) {
                ModuleKind::BranchOpen => {
                    self.bracket_free = false;
                    self.stack.push(i as u32);
                }
                ModuleKind::BranchClose => {
                    self.bracket_free = false;
                    if let Some(o) = self.stack.pop() {
                        if let Some(p) = self.partner.get_mut(o as usize) {
                            *p = i as u32;
                        }
                        if let Some(p) = self.partner.get_mut(i) {
                            *p = o;
                        }
                    }
                }
                _ => {}
            }
        }
    }

    /// The matching bracket of the bracket at `i`, if any.
    #[inline]
    pub fn partner(&self, i: usize) -> Option<usize> {
        match self.partner.get(i) {
            Some(&p) if p != NONE => Some(p as usize),
            _ => None,
        }
    }

    /// `true` if the last [`rebuild`](Self::rebuild) saw no bracket at all (then every
    /// context is made of neighbouring modules, ignored ones aside). `false` for an index
    /// never built.
    #[inline]
    pub fn bracket_free(&self) -> bool {
        self.bracket_free
    }

    /// Heap bytes reserved.
    pub fn heap_bytes(&self) -> usize {
        (self.partner.capacity() + self.stack.capacity()) * 4
    }
}

/// What the matchers need to know about a string.
pub trait ContextView {
    /// Number of modules.
    fn len(&self) -> usize;
    /// `true` if there are no modules.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Structural kind of module `i`.
    fn kind(&self, i: usize) -> ModuleKind;
    /// `true` if module `i` is in the ignore set.
    fn ignored(&self, i: usize) -> bool;
}

/// Matches a left-context pattern ending just before module `i`.
///
/// `eq(k, pos)` says whether pattern module `k` (0-based, in pattern order) matches the
/// string module at `pos`. On success the matched positions are written to `out` in
/// pattern order. Patterns containing brackets never match on the left.
pub fn match_left<T, V: ContextView + ?Sized>(
    view: &V,
    branches: &BranchIndex,
    i: usize,
    pattern: &[ContextItem<T>],
    mut eq: impl FnMut(&T, usize) -> bool,
    out: &mut Vec<u32>,
) -> bool {
    out.clear();
    let mut pos = i;
    for item in pattern.iter().rev() {
        let ContextItem::Module(want) = item else {
            return false;
        };
        loop {
            if pos == 0 {
                return false;
            }
            pos -= 1;
            match view.kind(pos) {
                ModuleKind::BranchOpen => continue,
                ModuleKind::BranchClose => match branches.partner(pos) {
                    Some(p) => {
                        pos = p;
                        continue;
                    }
                    None => return false,
                },
                _ => {
                    if view.ignored(pos) {
                        continue;
                    }
                    if eq(want, pos) {
                        out.push(pos as u32);
                        break;
                    }
                    return false;
                }
            }
        }
    }
    out.reverse();
    true
}

/// Matches a right-context pattern starting just after module `i`.
///
/// Same conventions as [`match_left`]; positions of the pattern's modules (not its
/// brackets) are written to `out` in pattern order.
pub fn match_right<T, V: ContextView + ?Sized>(
    view: &V,
    branches: &BranchIndex,
    i: usize,
    pattern: &[ContextItem<T>],
    mut eq: impl FnMut(&T, usize) -> bool,
    out: &mut Vec<u32>,
) -> bool {
    out.clear();
    let n = view.len();
    let mut pos = i + 1;
    for item in pattern {
        match item {
            ContextItem::Open => loop {
                if pos >= n {
                    return false;
                }
                match view.kind(pos) {
                    ModuleKind::BranchOpen => {
                        pos += 1;
                        break;
                    }
                    ModuleKind::Plain | ModuleKind::Cut if view.ignored(pos) => pos += 1,
                    _ => return false,
                }
            },
            ContextItem::Close => loop {
                if pos >= n {
                    return false;
                }
                match view.kind(pos) {
                    ModuleKind::BranchClose => {
                        pos += 1;
                        break;
                    }
                    ModuleKind::BranchOpen => match branches.partner(pos) {
                        Some(p) => pos = p + 1,
                        None => return false,
                    },
                    _ => pos += 1,
                }
            },
            ContextItem::Module(want) => loop {
                if pos >= n {
                    return false;
                }
                match view.kind(pos) {
                    ModuleKind::BranchOpen => match branches.partner(pos) {
                        Some(p) => pos = p + 1,
                        None => return false,
                    },
                    ModuleKind::BranchClose => return false,
                    _ => {
                        if view.ignored(pos) {
                            pos += 1;
                            continue;
                        }
                        if eq(want, pos) {
                            out.push(pos as u32);
                            pos += 1;
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

/// Index just past the end of the branch that contains position `from` (the position of
/// its closing `]`, or `n` at the top level). Used by the cut `%`.
pub(crate) fn end_of_branch<V: ContextView + ?Sized>(view: &V, from: usize) -> usize {
    let n = view.len();
    let mut depth = 0usize;
    let mut pos = from;
    while pos < n {
        match view.kind(pos) {
            ModuleKind::BranchOpen => depth += 1,
            ModuleKind::BranchClose => {
                if depth == 0 {
                    return pos;
                }
                depth -= 1;
            }
            _ => {}
        }
        pos += 1;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Chars(Vec<char>, &'static str);
    impl ContextView for Chars {
        fn len(&self) -> usize {
            self.0.len()
        }
        fn kind(&self, i: usize) -> ModuleKind {
            match self.0[i] {
                '[' => ModuleKind::BranchOpen,
                ']' => ModuleKind::BranchClose,
                '%' => ModuleKind::Cut,
                _ => ModuleKind::Plain,
            }
        }
        fn ignored(&self, i: usize) -> bool {
            self.1.contains(self.0[i])
        }
    }

    fn pat(s: &str) -> Vec<ContextItem<char>> {
        s.chars()
            .map(|c| match c {
                '[' => ContextItem::Open,
                ']' => ContextItem::Close,
                c => ContextItem::Module(c),
            })
            .collect()
    }

    fn run(s: &str, ign: &'static str, at: char, left: &str, right: &str) -> bool {
        let v = Chars(s.chars().collect(), ign);
        let mut b = BranchIndex::default();
        b.rebuild(v.len(), |i| v.kind(i));
        let i = v.0.iter().position(|&c| c == at).unwrap();
        let mut out = Vec::new();
        match_left(&v, &b, i, &pat(left), |&c, p| v.0[p] == c, &mut out)
            && match_right(&v, &b, i, &pat(right), |&c, p| v.0[p] == c, &mut out)
    }

    #[test]
    fn abop_figure_1_25() {
        // ABOP §1.8: BC < S > G[H]M applies to S in ABC[DE][SG[HI[JK]L]MNO].
        let s = "ABC[DE][SG[HI[JK]L]MNO]";
        assert!(run(s, "", 'S', "BC", "G[H]M"));
        assert!(!run(s, "", 'S', "DE", ""));
        assert!(!run(s, "", 'S', "", "GH"));
        assert!(run(s, "", 'S', "", "GM"));
        assert!(!run(s, "", 'S', "", "GMNOX"));
    }

    #[test]
    fn ignore_set_and_end_of_branch() {
        assert!(run("A+-B", "+-", 'B', "A", ""));
        assert!(!run("A+-B", "", 'B', "A", ""));
        assert!(!run("[A]B", "", 'A', "", "B"));
        assert!(run("X[A]B", "", 'A', "X", ""));
        let v = Chars("A[B%C[D]E]F".chars().collect(), "");
        assert_eq!(end_of_branch(&v, 4), 9);
        assert_eq!(end_of_branch(&v, 10), 11);
    }
}
