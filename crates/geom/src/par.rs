//! The one switch between parallel (rayon) and serial execution for every polis crate.
//!
//! Crates that run work in parallel write their loops against this module instead of
//! against rayon: `use polis_geom::par::prelude::*;` gives `par_iter`, `par_iter_mut`,
//! `into_par_iter` and `par_extend`, and [`join`], [`run_beside`], [`install`] and
//! [`map_costliest_first`] cover the other patterns. With the feature `parallel` (on
//! through the `parallel` feature of polis-stats, polis-export and the facade, all on by
//! default) they are rayon's; without it they are plain iterators and sequential calls,
//! so a build without rayon (for example for wasm32 or a single-threaded embedder) needs
//! no change at any call site.
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

/// Maps every item by `f` on the thread pool, longest job first: the items are started in
/// the order of their `cost` estimates, largest first (ties in item order), each by
/// whichever thread is free next, and the results come back in item order. Serially it
/// maps them in item order.
///
/// With many jobs of uneven size, handing them out largest first leaves only small ones
/// for the end, so the threads finish together (Graham's longest-processing-time rule:
/// at most 4/3 of the best possible wall time with exact costs, and close to it when no
/// job is large); rayon's splitting of the items in halves may leave a large one for
/// last, with the other threads idle while it runs. The costs are only estimates: a
/// wrong one costs time, never a different result.
///
/// # Limitations
///
/// * It waits for every job, and keeps one claiming loop per pool thread busy until the
///   jobs run out (jobs that call rayon themselves run on the same pool).
/// * Jobs are claimed one at a time through one shared counter: meant for jobs far
///   longer than a counter's increment (cells, not pixels).
///
/// # Guarantees
///
/// * The results are `f`'s, in item order, whatever the costs, the thread count and the
///   order the jobs ran in: the costs decide only when each job starts.
/// * `cost` runs once per item, on the calling thread.
pub fn map_costliest_first<T, R, C, F>(items: &[T], cost: C, f: F) -> Vec<R>
where
    T: Sync,
    R: Send,
    C: Fn(&T) -> f64,
    F: Fn(&T) -> R + Sync,
{
    #[cfg(feature = "parallel")]
    {
        use std::sync::Mutex;
        use std::sync::atomic::{AtomicUsize, Ordering};
        let costs: Vec<f64> = items.iter().map(cost).collect();
        let mut order: Vec<usize> = (0..items.len()).collect();
        order.sort_by(|&a, &b| {
            let (ca, cb) = (costs.get(a), costs.get(b));
            cb.zip(ca)
                .map_or(std::cmp::Ordering::Equal, |(cb, ca)| cb.total_cmp(ca))
                .then(a.cmp(&b))
        });
        let slots: Vec<Mutex<Option<R>>> = items.iter().map(|_| Mutex::new(None)).collect();
        let next = AtomicUsize::new(0);
        // One claiming loop per pool thread: each takes the next job in `order` until
        // none is left.
        let work = || {
            while let Some(&i) = order.get(next.fetch_add(1, Ordering::Relaxed)) {
                if let (Some(item), Some(slot)) = (items.get(i), slots.get(i)) {
                    let r = f(item);
                    if let Ok(mut slot) = slot.lock() {
                        *slot = Some(r);
                    }
                }
            }
        };
        let threads = rayon::current_num_threads().min(items.len()).max(1);
        rayon::scope(|s| {
            for _ in 1..threads {
                s.spawn(|_| work());
            }
            work();
        });
        // Every slot was filled: a job that panicked has propagated its panic out of the
        // scope above.
        slots
            .into_iter()
            .filter_map(|m| m.into_inner().ok().flatten())
            .collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        let _ = cost;
        items.iter().map(f).collect()
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

    /// Whatever the costs (ties, NaN, all equal) and the thread count, the results are
    /// the items' own, in item order.
    #[test]
    fn costliest_first_keeps_item_order() {
        let v: Vec<u64> = (0..300).collect();
        let want: Vec<u64> = v.iter().map(|x| x * 3 + 1).collect();
        let costs: [fn(&u64) -> f64; 4] = [
            |&x| x as f64,
            |&x| -(x as f64),
            |&x| ((x * 7919) % 13) as f64,
            |&x| if x % 5 == 0 { f64::NAN } else { 1.0 },
        ];
        for threads in [1, 2, 5] {
            for cost in costs {
                let got = install(threads, || map_costliest_first(&v, cost, |x| x * 3 + 1));
                assert_eq!(got.as_ref(), Ok(&want));
            }
        }
        let none: Vec<u64> = Vec::new();
        assert!(map_costliest_first(&none, |_| 1.0, |x| *x).is_empty());
    }
}
