//! A stack of `Copy` items kept inline up to `N` and in a `Vec` beyond: for the short,
//! hot scratch lists of the spatial grid's walks and planar insertion's route, which
//! are nearly always a few items long and would otherwise allocate per query or per
//! segment.

/// Items kept in `inline[..len]` while there are at most `N`; once more are pushed,
/// all of them move to `spill`, which then holds the whole stack until it empties.
pub(crate) struct InlineVec<T: Copy, const N: usize> {
    inline: [T; N],
    len: usize,
    spill: Vec<T>,
}

impl<T: Copy, const N: usize> InlineVec<T, N> {
    /// An empty stack; `fill` only initialises the unused inline slots.
    pub(crate) fn new(fill: T) -> Self {
        InlineVec {
            inline: [fill; N],
            len: 0,
            spill: Vec::new(),
        }
    }

    pub(crate) fn as_slice(&self) -> &[T] {
        if self.spill.is_empty() {
            self.inline.get(..self.len).unwrap_or(&[])
        } else {
            &self.spill
        }
    }

    pub(crate) fn last(&self) -> Option<T> {
        self.as_slice().last().copied()
    }

    pub(crate) fn push(&mut self, item: T) {
        if self.spill.is_empty() {
            if let Some(slot) = self.inline.get_mut(self.len) {
                *slot = item;
                self.len += 1;
                return;
            }
            self.spill.extend_from_slice(&self.inline);
        }
        self.spill.push(item);
    }

    pub(crate) fn pop(&mut self) {
        if self.spill.is_empty() {
            self.len = self.len.saturating_sub(1);
        } else {
            self.spill.pop();
            if self.spill.is_empty() {
                // Emptied from a spill: the inline part is stale, the stack is empty.
                self.len = 0;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::InlineVec;

    /// Pushes and pops across the inline/spill boundary agree with a `Vec`.
    #[test]
    fn agrees_with_a_vec_across_the_spill() {
        let mut s: InlineVec<u32, 3> = InlineVec::new(0);
        let mut v: Vec<u32> = Vec::new();
        let ops = [1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0];
        for (i, &op) in ops.iter().enumerate() {
            if op == 1 {
                s.push(i as u32);
                v.push(i as u32);
            } else {
                s.pop();
                v.pop();
            }
            assert_eq!(s.as_slice(), v.as_slice(), "after op {i}");
            assert_eq!(s.last(), v.last().copied());
        }
    }
}
