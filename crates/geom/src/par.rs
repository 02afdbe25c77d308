//! The one switch between parallel (rayon) and serial execution for every polis crate.
//!
//! Crates that run work in parallel write their loops against this module instead of
//! against rayon: `use polis_geom::par::prelude::*;` gives `par_iter`, `par_iter_mut`,
//! `into_par_iter` and `par_extend`, and [`join`], [`run_beside`] and [`install`] cover
//! the other patterns. With the feature `parallel` (on through the `parallel` feature of
//! polis-stats, polis-export and the facade, all on by default) they are rayon's; without
//! it they are plain iterators and sequential calls, so a build without rayon (for
//! example for wasm32 or a single-threaded embedder) needs no change at any call site.
//!
//! ## Guarantees
//!
//! * **Same results either way.** Every polis caller gathers results in input order
//!   (`collect`, `zip`, `enumerate`, `count`, `par_extend` keep order in both modes), so a
//!   serial build writes the same bytes as a parallel one at any thread count (tested by
//!   the facade's thread-count tests, run in both modes by CI).
//! * **Same bounds either way.** [`join`], [`run_beside`] and [`install`] ask for `Send`
//!   closures in both modes, so code that compiles serially also compiles in parallel.
//!
//! ## Limitations
//!
//! * Features unify across a build: if any crate of the build turns `parallel` on, every
//!   polis crate runs in parallel.
//! * Serially, [`install`] ignores the thread count (one thread, the caller's).
//! * The serial `prelude` covers the methods polis uses: the iterators it returns are
//!   `std` iterators, which lack rayon-only adaptors (`with_min_len`, rayon's two-argument
//!   `reduce`, `fold` into partial results); CI's `--no-default-features` builds catch a
//!   call site that uses one.

/// Whether this build runs polis' parallel loops on rayon (feature `parallel`).
pub const PARALLEL: bool = cfg!(feature = "parallel");

/// `par_iter`, `par_iter_mut`, `into_par_iter` and `par_extend`: rayon's with the feature
/// `parallel`, ordered `std` iterators without it.
pub mod prelude {
    #[cfg(feature = "parallel")]
    pub use rayon::prelude::*;

    #[cfg(not(feature = "parallel"))]
    pub use super::serial::{
        IntoParallelIterator, IntoParallelRefIterator, IntoParallelRefMutIterator, ParallelExtend,
    };
}

/// Runs `a` and `b`, potentially in parallel, and returns both results (`rayon::join`;
/// serially `a` then `b`).
pub fn join<A, B, RA, RB>(a: A, b: B) -> (RA, RB)
where
    A: FnOnce() -> RA + Send,
    B: FnOnce() -> RB + Send,
    RA: Send,
    RB: Send,
{
    #[cfg(feature = "parallel")]
    {
        rayon::join(a, b)
    }
    #[cfg(not(feature = "parallel"))]
    {
        (a(), b())
    }
}

/// Runs `foreground` on the calling thread while `background` runs on the thread pool,
/// and returns both results once both are done (serially `background` first, then
/// `foreground`). Unlike [`join`], `foreground` need not be `Send`: it may hold a
/// writer that cannot leave its thread (the OBJ writer formats the next batch in the
/// background while writing the last one).
pub fn run_beside<F, B, RF, RB>(background: B, foreground: F) -> (RF, RB)
where
    B: FnOnce() -> RB + Send,
    F: FnOnce() -> RF,
    RB: Send,
{
    #[cfg(feature = "parallel")]
    {
        let mut back = None;
        let front = rayon::in_place_scope(|s| {
            s.spawn(|_| back = Some(background()));
            foreground()
        });
        match back {
            Some(back) => (front, back),
            // The scope waits for its spawned job, which always stores its result; if
            // `background` panicked, the scope has already propagated the panic.
            None => unreachable!("in_place_scope returned before its spawned job finished"),
        }
    }
    #[cfg(not(feature = "parallel"))]
    {
        let back = background();
        (foreground(), back)
    }
}

/// A thread pool of the asked size could not be started (the operating system refused
/// threads). Only the parallel build can fail so.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("cannot start {threads} worker threads: {message}")]
pub struct PoolError {
    /// Threads asked for.
    pub threads: usize,
    /// Why it failed.
    pub message: String,
}

/// Runs `job` on a fresh pool of `threads` workers; every parallel loop inside it uses
/// that pool (`rayon::ThreadPool::install`). Serially `job` runs on the calling thread
/// and `threads` is ignored.
///
/// # Errors
/// [`PoolError`] when the pool cannot be built.
pub fn install<T, J>(threads: usize, job: J) -> Result<T, PoolError>
where
    T: Send,
    J: FnOnce() -> T + Send,
{
    #[cfg(feature = "parallel")]
    {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| PoolError {
                threads,
                message: e.to_string(),
            })?;
        Ok(pool.install(job))
    }
    #[cfg(not(feature = "parallel"))]
    {
        let _ = threads;
        Ok(job())
    }
}

/// The serial stand-ins for rayon's traits (used without the feature `parallel`).
#[cfg(not(feature = "parallel"))]
mod serial {
    /// `into_par_iter()`: the value's ordinary iterator.
    pub trait IntoParallelIterator: IntoIterator + Sized {
        /// The value's ordinary iterator (serial build).
        fn into_par_iter(self) -> Self::IntoIter {
            self.into_iter()
        }
    }
    impl<I: IntoIterator> IntoParallelIterator for I {}

    /// `par_iter()`: iteration by shared reference.
    pub trait IntoParallelRefIterator<'a> {
        /// The iterator over `&item`.
        type Iter: Iterator;
        /// Iterates by shared reference (serial build).
        fn par_iter(&'a self) -> Self::Iter;
    }
    impl<'a, C: ?Sized + 'a> IntoParallelRefIterator<'a> for C
    where
        &'a C: IntoIterator,
    {
        type Iter = <&'a C as IntoIterator>::IntoIter;
        fn par_iter(&'a self) -> Self::Iter {
            self.into_iter()
        }
    }

    /// `par_iter_mut()`: iteration by mutable reference.
    pub trait IntoParallelRefMutIterator<'a> {
        /// The iterator over `&mut item`.
        type Iter: Iterator;
        /// Iterates by mutable reference (serial build).
        fn par_iter_mut(&'a mut self) -> Self::Iter;
    }
    impl<'a, C: ?Sized + 'a> IntoParallelRefMutIterator<'a> for C
    where
        &'a mut C: IntoIterator,
    {
        type Iter = <&'a mut C as IntoIterator>::IntoIter;
        fn par_iter_mut(&'a mut self) -> Self::Iter {
            self.into_iter()
        }
    }

    /// `par_extend()`: `Extend::extend`, in order.
    pub trait ParallelExtend<T> {
        /// Appends the items in order (serial build).
        fn par_extend<I: IntoIterator<Item = T>>(&mut self, items: I);
    }
    impl<T, C: Extend<T>> ParallelExtend<T> for C {
        fn par_extend<I: IntoIterator<Item = T>>(&mut self, items: I) {
            self.extend(items);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::prelude::*;
    use super::*;

    #[test]
    fn loops_keep_input_order() {
        let v: Vec<u64> = (0..1000).collect();
        let squares: Vec<u64> = v.par_iter().map(|x| x * x).collect();
        assert_eq!(squares, v.iter().map(|x| x * x).collect::<Vec<_>>());
        let mut w = v.clone();
        w.par_iter_mut().for_each(|x| *x += 1);
        assert_eq!(w[999], 1000);
        let mut out = vec![7u64];
        out.par_extend((0..5u64).into_par_iter().map(|i| i * 2));
        assert_eq!(out, [7, 0, 2, 4, 6, 8]);
        let evens = (0..1000u64).into_par_iter().filter(|i| i % 2 == 0).count();
        assert_eq!(evens, 500);
    }

    #[test]
    fn join_run_beside_and_install_return_both_results() {
        assert_eq!(join(|| 1, || "b"), (1, "b"));
        let mut log = Vec::new();
        let (front, back) = run_beside(|| (0..100u32).sum::<u32>(), || log.push(1));
        assert_eq!((front, back, log), ((), 4950, vec![1]));
        assert_eq!(install(3, || join(|| 2, || 3)), Ok((2, 3)));
    }
}
