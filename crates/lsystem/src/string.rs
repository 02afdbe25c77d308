//! Module strings: the storage the derivation engine rewrites.
//!
//! Two storages ship with the crate:
//!
//! * `Vec<M>` for typed modules ([`Module`](crate::Module)), one value per module;
//! * [`ParamString`] for numeric-parameter modules (the text grammar): a symbol id and an
//!   offset per module plus one flat arena of `f64` parameters, so deriving never allocates
//!   per module.

/// A string of modules that the engine can copy from and append to.
///
/// The engine keeps two strings and swaps them between steps (double buffering), so
/// [`clear`](ModuleString::clear) must keep the allocation.
pub trait ModuleString: Default + Clone {
    /// Number of modules.
    fn len(&self) -> usize;
    /// `true` if there are no modules.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Removes every module, keeping the capacity.
    fn clear(&mut self);
    /// Appends a copy of module `i` of `src` (identity production).
    fn push_copy(&mut self, src: &Self, i: usize);
    /// Bytes of heap memory currently reserved by this string.
    fn heap_bytes(&self) -> usize;
    /// Reserves room for `modules` modules shaped on average like those of `like` (for
    /// [`ParamString`]: as many parameters per module), so that a derivation step that
    /// writes about that many does not grow the buffer by repeated doubling and copying.
    /// Only capacity changes. Default: nothing.
    fn reserve_like(&mut self, _like: &Self, _modules: usize) {}
}

impl<M: Clone> ModuleString for Vec<M> {
    #[inline]
    fn len(&self) -> usize {
        Vec::len(self)
    }
    #[inline]
    fn clear(&mut self) {
        Vec::clear(self);
    }
    #[inline]
    fn push_copy(&mut self, src: &Self, i: usize) {
        if let Some(m) = src.get(i) {
            self.push(m.clone());
        }
    }
    fn heap_bytes(&self) -> usize {
        self.capacity() * std::mem::size_of::<M>()
    }
    fn reserve_like(&mut self, _like: &Self, modules: usize) {
        self.reserve(modules.saturating_sub(self.len()));
    }
}

/// One module's header in a [`ParamString`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Head {
    symbol: u32,
    start: u32,
}

/// A string of numeric-parameter modules: symbol ids with `f64` parameters in a flat arena.
///
/// Module `i` has symbol [`symbol(i)`](Self::symbol) and parameters
/// [`params(i)`](Self::params). 8 bytes per module plus 8 bytes per parameter. The
/// meaning of symbol ids is given by the [`Grammar`](crate::Grammar) that produced the
/// string ([`Grammar::symbol_name`](crate::Grammar::symbol_name)).
#[derive(Debug, Default, PartialEq)]
pub struct ParamString {
    heads: Vec<Head>,
    params: Vec<f64>,
}

impl Clone for ParamString {
    fn clone(&self) -> Self {
        Self {
            heads: self.heads.clone(),
            params: self.params.clone(),
        }
    }

    /// Reuses this string's buffers (what [`Derivation::restart`](crate::Derivation::restart)
    /// relies on to restart without allocating).
    fn clone_from(&mut self, source: &Self) {
        self.heads.clone_from(&source.heads);
        self.params.clone_from(&source.params);
    }
}

impl ParamString {
    /// An empty string.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty string with room for `modules` modules and `params` parameters.
    pub fn with_capacity(modules: usize, params: usize) -> Self {
        Self {
            heads: Vec::with_capacity(modules),
            params: Vec::with_capacity(params),
        }
    }

    /// Number of modules.
    #[inline]
    pub fn len(&self) -> usize {
        self.heads.len()
    }

    /// `true` if empty.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.heads.is_empty()
    }

    /// Total number of parameters of all modules.
    pub fn param_count(&self) -> usize {
        self.params.len()
    }

    /// Symbol id of module `i` (`u32::MAX` if `i` is out of range).
    #[inline]
    pub fn symbol(&self, i: usize) -> u32 {
        self.heads.get(i).map_or(u32::MAX, |h| h.symbol)
    }

    #[inline]
    fn range(&self, i: usize) -> (usize, usize) {
        let start = self.heads.get(i).map_or(0, |h| h.start as usize);
        let end = self
            .heads
            .get(i + 1)
            .map_or(self.params.len(), |h| h.start as usize);
        (start, end)
    }

    /// Parameters of module `i` (empty if `i` is out of range).
    #[inline]
    pub fn params(&self, i: usize) -> &[f64] {
        if i >= self.heads.len() {
            return &[];
        }
        let (s, e) = self.range(i);
        self.params.get(s..e).unwrap_or(&[])
    }

    /// Mutable parameters of module `i` (empty if `i` is out of range). The count is fixed.
    #[inline]
    pub fn params_mut(&mut self, i: usize) -> &mut [f64] {
        if i >= self.heads.len() {
            return &mut [];
        }
        let (s, e) = self.range(i);
        self.params.get_mut(s..e).unwrap_or(&mut [])
    }

    /// Appends a module. Parameters beyond the 32-bit arena limit are an error.
    pub fn push(&mut self, symbol: u32, params: &[f64]) -> crate::Result<()> {
        if self.params.len() + params.len() > MAX_PARAMS {
            return Err(crate::LsystemError::TooManyParameters { max: MAX_PARAMS });
        }
        self.begin(symbol);
        self.params.extend_from_slice(params);
        Ok(())
    }

    /// Starts a module whose parameters follow with [`push_param`](Self::push_param).
    /// The caller checks [`arena_overflowed`](Self::arena_overflowed) afterwards.
    #[inline]
    pub(crate) fn begin(&mut self, symbol: u32) {
        self.heads.push(Head {
            symbol,
            start: self.params.len() as u32,
        });
    }

    /// Appends a parameter to the last module.
    #[inline]
    pub(crate) fn push_param(&mut self, v: f64) {
        self.params.push(v);
    }

    /// `true` once the arena has outgrown its 32-bit offsets.
    #[inline]
    pub(crate) fn arena_overflowed(&self) -> bool {
        self.params.len() > MAX_PARAMS
    }

    /// Iterates `(symbol, params)` pairs.
    pub fn iter(&self) -> impl Iterator<Item = (u32, &[f64])> + '_ {
        (0..self.len()).map(move |i| (self.symbol(i), self.params(i)))
    }

    /// Removes modules from `len` on.
    pub fn truncate(&mut self, len: usize) {
        if len < self.heads.len() {
            let start = self.range(len).0;
            self.heads.truncate(len);
            self.params.truncate(start);
        }
    }
}

/// Most parameters a [`ParamString`] can hold (32-bit offsets).
pub const MAX_PARAMS: usize = u32::MAX as usize;

impl ModuleString for ParamString {
    #[inline]
    fn len(&self) -> usize {
        self.heads.len()
    }
    #[inline]
    fn clear(&mut self) {
        self.heads.clear();
        self.params.clear();
    }
    #[inline]
    fn push_copy(&mut self, src: &Self, i: usize) {
        if i < src.heads.len() {
            let (s, e) = src.range(i);
            self.begin(src.symbol(i));
            match src.params.get(s..e) {
                // One or no parameter (most modules): a plain push, not a `memcpy` call.
                Some(&[v]) => self.params.push(v),
                Some(p) => self.params.extend_from_slice(p),
                None => {}
            }
        }
    }
    fn heap_bytes(&self) -> usize {
        self.heads.capacity() * std::mem::size_of::<Head>()
            + self.params.capacity() * std::mem::size_of::<f64>()
    }
    fn reserve_like(&mut self, like: &Self, modules: usize) {
        let per_module = like.params.len() as f64 / like.heads.len().max(1) as f64;
        let params = (modules as f64 * per_module).ceil().min(MAX_PARAMS as f64) as usize;
        self.heads.reserve(modules.saturating_sub(self.heads.len()));
        self.params
            .reserve(params.saturating_sub(self.params.len()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn param_string_layout() {
        let mut s = ParamString::new();
        s.push(3, &[1.0, 2.0]).unwrap();
        s.push(4, &[]).unwrap();
        s.push(5, &[7.0]).unwrap();
        assert_eq!(s.len(), 3);
        assert_eq!(s.params(0), &[1.0, 2.0]);
        assert_eq!(s.params(1), &[] as &[f64]);
        assert_eq!(s.params(2), &[7.0]);
        assert_eq!(s.params(9), &[] as &[f64]);
        s.params_mut(2)[0] = 8.0;
        let mut t = ParamString::new();
        t.push_copy(&s, 2);
        t.push_copy(&s, 0);
        t.push_copy(&s, 99);
        assert_eq!(
            t.iter().collect::<Vec<_>>(),
            vec![(5, &[8.0][..]), (3, &[1.0, 2.0][..])]
        );
        s.truncate(1);
        assert_eq!(s.len(), 1);
        assert_eq!(s.param_count(), 2);
    }
}
