//! The kernel's data-parallel loops, on every core natively and in a web page.
//!
//! Each loop is a map over indices `0..count` whose results are gathered in index order, so the
//! output is bit for bit the same on any number of threads (tests compare pools of one and of
//! several threads). Natively the loops run on rayon's pool. In a web page rayon cannot be
//! used from the browser's main thread, which may not wait (`Atomics.wait` is refused there,
//! and rayon's joins wait), so the threaded page installs [`Helpers`] instead: Web Workers on
//! the page's shared memory. A loop then runs on the calling thread *and* the helpers, each
//! claiming chunks of indices from a shared counter until none are left; the caller only spins
//! for the last chunks to finish. A loop inside a loop runs on the thread that meets it.
//!
//! Without helpers and off the web page (native, the single-threaded page, the tests) the
//! loops are rayon's.

use std::cell::{Cell, UnsafeCell};
use std::mem::MaybeUninit;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rayon::prelude::*;

/// Threads that join the calling thread in a loop (the threaded web page's Web Workers).
#[derive(Clone, Copy, Debug)]
pub struct Helpers {
    /// Runs `work` on the calling thread and on every helper, and returns when all of them
    /// have returned from it. A call made while the calling thread is already inside `work`
    /// (a loop in a loop) runs `work` on the calling thread alone.
    pub run: fn(&(dyn Fn() + Sync)),
    /// The threads a loop runs on: the calling thread and the helpers.
    pub threads: usize,
}

static HELPERS: OnceLock<Helpers> = OnceLock::new();

thread_local! {
    /// Helpers for this thread's loops only ([`with_helpers`]).
    static LOCAL_HELPERS: Cell<Option<Helpers>> = const { Cell::new(None) };
}

/// The helpers this thread's loops run on, if any.
fn current_helpers() -> Option<Helpers> {
    LOCAL_HELPERS
        .with(Cell::get)
        .or_else(|| HELPERS.get().copied())
}

/// Runs `f` with the loops this thread enters on `helpers` (other threads keep theirs): the
/// page's scheme natively, for tests and benches.
pub fn with_helpers<R>(helpers: Helpers, f: impl FnOnce() -> R) -> R {
    let previous = LOCAL_HELPERS.with(|local| local.replace(Some(helpers)));
    let result = f();
    LOCAL_HELPERS.with(|local| local.set(previous));
    result
}

/// Helpers natively, for tests ([`with_helpers`]): `work` on the calling thread and on three
/// scoped threads; a loop met inside `work` runs on its thread alone.
pub const SCOPED_HELPERS: Helpers = Helpers {
    run: run_on_scoped_threads,
    threads: 4,
};

fn run_on_scoped_threads(work: &(dyn Fn() + Sync)) {
    thread_local! {
        static INSIDE: Cell<bool> = const { Cell::new(false) };
    }
    if INSIDE.with(Cell::get) {
        return work();
    }
    let inside = || {
        INSIDE.with(|inside| inside.set(true));
        work();
        INSIDE.with(|inside| inside.set(false));
    };
    std::thread::scope(|scope| {
        for _ in 0..3 {
            scope.spawn(inside);
        }
        inside();
    });
}

/// No helpers: every loop on the calling thread alone, with [`threads`] 1 (the
/// single-threaded page), for tests that compare one thread with many ([`with_helpers`]).
pub const ONE_THREAD: Helpers = Helpers {
    run: run_here,
    threads: 1,
};

fn run_here(work: &(dyn Fn() + Sync)) {
    work();
}

/// Installs the helpers every later loop runs on (instead of rayon's pool). The first
/// installation stays; returns whether this one was it.
pub fn set_helpers(helpers: Helpers) -> bool {
    HELPERS.set(helpers).is_ok()
}

/// The number of threads the loops run on.
pub fn threads() -> usize {
    match current_helpers() {
        Some(helpers) => helpers.threads,
        None => rayon::current_num_threads(),
    }
}

/// A value computed on first use and shared by every thread after, that never makes a thread
/// wait. Where threads ask for it at once, each computes it and the first to finish stores it;
/// the others drop their copies and take the stored one (the value is the same whoever
/// computes it, so a loop's results stay the same on any number of threads).
///
/// The threaded page's main thread may not wait: `Atomics.wait` traps there, and the trap
/// leaves the editor's runner borrowed, so the page stops drawing. A `std::sync::OnceLock`
/// waits while another thread runs its initializer, so a lazily computed value that a loop's
/// threads share is one of these instead (`once_cell`'s race cell, a pointer set by one
/// compare-and-swap).
pub struct RaceCell<T>(once_cell::race::OnceBox<T>);

impl<T> RaceCell<T> {
    pub const fn new() -> Self {
        Self(once_cell::race::OnceBox::new())
    }

    /// The value, if it has been computed.
    pub fn get(&self) -> Option<&T> {
        self.0.get()
    }

    /// Stores `value` where none is stored yet; else gives it back.
    pub fn set(&self, value: T) -> Result<(), T> {
        self.0.set(Box::new(value)).map_err(|value| *value)
    }

    /// The value, computed by `f` where no thread has stored it yet.
    pub fn get_or_init(&self, f: impl FnOnce() -> T) -> &T {
        self.0.get_or_init(|| Box::new(f()))
    }
}

impl<T> Default for RaceCell<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Clone> Clone for RaceCell<T> {
    fn clone(&self) -> Self {
        Self(self.0.clone())
    }
}

impl<T: std::fmt::Debug> std::fmt::Debug for RaceCell<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("RaceCell").field(&self.get()).finish()
    }
}

/// `f(0), f(1), …, f(count - 1)` on every core, in index order.
pub fn map<T: Send>(count: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    map_init(count, || (), |_, i| f(i))
}

/// `f(state, i)` for every `i` in `0..count` on every core, in index order, where each thread
/// taking part makes its own `state` with `init` (a scratch buffer) and uses it for every index
/// it takes.
pub fn map_init<S, T: Send>(
    count: usize,
    init: impl Fn() -> S + Sync + Send,
    f: impl Fn(&mut S, usize) -> T + Sync + Send,
) -> Vec<T> {
    let helpers = current_helpers();
    // One index (rayon is never touched where there are helpers), or a pool of one thread:
    // here, without handing the loop to the pool's thread and waiting for it (a wake-up and a
    // sleep per loop, which many small loops felt).
    if count <= 1 || (helpers.is_none() && rayon::current_num_threads() == 1) {
        let mut state = init();
        return (0..count).map(|i| f(&mut state, i)).collect();
    }
    match helpers {
        Some(helpers) => map_on_helpers(&helpers, count, &init, &f),
        None => (0..count).into_par_iter().map_init(init, f).collect(),
    }
}

/// `f(k, chunk)` for every chunk `out[k * width..(k + 1) * width]` of `out` (the last may be
/// shorter), on every core: a loop that writes its results in place, where [`map`] would
/// gather them into a new vector first (for large outputs the copy and the fresh pages of
/// that vector cost as much as the work).
pub fn fill_chunks<T: Send>(
    out: &mut [T],
    width: usize,
    f: impl Fn(usize, &mut [T]) + Sync + Send,
) {
    let width = width.max(1);
    let count = out.len().div_ceil(width);
    if count <= 1 || (current_helpers().is_none() && rayon::current_num_threads() == 1) {
        out.chunks_mut(width).enumerate().for_each(|(k, c)| f(k, c));
        return;
    }
    let len = out.len();
    let base = SharedSlice(out.as_mut_ptr());
    map(count, |k| {
        let start = k * width;
        let end = (start + width).min(len);
        // SAFETY: chunk k is `out[start..end]`, inside `out` and touched by this call alone
        // (each index is taken once); `out` is borrowed mutably for the whole loop.
        let chunk = unsafe { std::slice::from_raw_parts_mut(base.at(start), end - start) };
        f(k, chunk);
    });
}

/// The start of a slice whose disjoint chunks several threads write ([`fill_chunks`]).
struct SharedSlice<T>(*mut T);

// SAFETY: the threads write disjoint chunks only, and `T: Send`.
unsafe impl<T: Send> Sync for SharedSlice<T> {}
unsafe impl<T: Send> Send for SharedSlice<T> {}

impl<T> SharedSlice<T> {
    /// The element `offset` places on. SAFETY: `offset` lies within the slice.
    unsafe fn at(&self, offset: usize) -> *mut T {
        unsafe { self.0.add(offset) }
    }
}

/// `f(i, item)` for every item, on every core, each item moved into its call.
pub fn for_each_owned<T: Send>(items: Vec<T>, f: impl Fn(usize, T) + Sync + Send) {
    let slots: Vec<Slot<Option<T>>> = items.into_iter().map(|t| Slot::new(Some(t))).collect();
    map(slots.len(), |i| {
        // SAFETY: index i is taken by exactly one call of this closure.
        if let Some(item) = unsafe { slots[i].take() } {
            f(i, item);
        }
    });
}

/// Indices a thread claims at a time: about eight chunks per thread, for balance.
fn chunk_size(count: usize, threads: usize) -> usize {
    (count / (8 * threads.max(1))).max(1)
}

/// A value one thread writes or takes, at an index no other thread touches.
struct Slot<T>(UnsafeCell<T>);

// SAFETY: each slot is accessed by one thread at a time (the one that claimed its index; the
// caller reads them all after every thread has finished).
unsafe impl<T: Send> Sync for Slot<T> {}

impl<T> Slot<T> {
    fn new(value: T) -> Self {
        Slot(UnsafeCell::new(value))
    }
}

impl<T> Slot<Option<T>> {
    /// The value, leaving nothing. SAFETY: no other thread may touch this slot meanwhile.
    unsafe fn take(&self) -> Option<T> {
        unsafe { (*self.0.get()).take() }
    }
}

/// The loop on the calling thread and the helpers: each claims `chunk_size` indices at a time
/// from a shared counter and writes their results into their slots.
fn map_on_helpers<S, T: Send>(
    helpers: &Helpers,
    count: usize,
    init: &(impl Fn() -> S + Sync),
    f: &(impl Fn(&mut S, usize) -> T + Sync),
) -> Vec<T> {
    let chunk = chunk_size(count, helpers.threads);
    let next = AtomicUsize::new(0);
    let results: Vec<Slot<MaybeUninit<T>>> = (0..count)
        .map(|_| Slot::new(MaybeUninit::uninit()))
        .collect();
    let written = AtomicUsize::new(0);
    let panicked = AtomicBool::new(false);
    let work = || {
        let mut state = None;
        loop {
            let start = next.fetch_add(chunk, Ordering::Relaxed);
            if start >= count {
                break;
            }
            let state = state.get_or_insert_with(init);
            let end = (start + chunk).min(count);
            for (i, slot) in results[start..end].iter().enumerate() {
                // A panic leaves the chunk uncounted, so nothing reads its slots.
                let value = f(state, start + i);
                // SAFETY: the slot belongs to this chunk, claimed by this thread alone.
                unsafe { (*slot.0.get()).write(value) };
            }
            written.fetch_add(end - start, Ordering::Release);
        }
    };
    (helpers.run)(&|| {
        if std::panic::catch_unwind(std::panic::AssertUnwindSafe(&work)).is_err() {
            panicked.store(true, Ordering::Relaxed);
        }
    });
    if panicked.load(Ordering::Relaxed) || written.load(Ordering::Acquire) != count {
        // The written results leak rather than drop (which ones is not known here).
        panic!("a parallel loop's work panicked");
    }
    results
        .into_iter()
        // SAFETY: every index was written (`written` counted each chunk once, whole).
        .map(|slot| unsafe { slot.0.into_inner().assume_init() })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A thread that asks for a `RaceCell`'s value while another is computing it does not
    /// wait for it (a `OnceLock` would, and this test would time out): it computes its own,
    /// which is stored first, and the slow thread gets that one too.
    #[test]
    fn a_race_cell_never_waits_for_the_thread_computing_it() {
        let cell = &RaceCell::new();
        let (started, computing) = std::sync::mpsc::channel();
        let (finished, done) = std::sync::mpsc::channel::<()>();
        std::thread::scope(|scope| {
            let slow = scope.spawn(move || {
                *cell.get_or_init(|| {
                    started.send(()).unwrap();
                    // Computing until the other thread has its value.
                    done.recv_timeout(std::time::Duration::from_secs(20))
                        .expect("the other thread waited for this one");
                    1
                })
            });
            computing.recv().unwrap();
            let fast = *cell.get_or_init(|| 2);
            finished.send(()).unwrap();
            assert_eq!(fast, 2);
            assert_eq!(slow.join().unwrap(), 2);
        });
        assert_eq!(cell.get(), Some(&2));
        let copy = cell.clone();
        assert_eq!(copy.get(), Some(&2));
    }

    #[test]
    fn a_map_returns_its_results_in_index_order() {
        let squares = map(1000, |i| i * i);
        assert!(squares.iter().enumerate().all(|(i, &s)| s == i * i));
        // A loop in a loop.
        let nested = map(8, |i| map(i, |j| j).into_iter().sum::<usize>());
        assert_eq!(nested, vec![0, 0, 1, 3, 6, 10, 15, 21]);
        // Each thread's state is its own: the sums of the indices it took add up.
        let taken = AtomicUsize::new(0);
        let out = map_init(
            500,
            || 0usize,
            |seen, i| {
                *seen += 1;
                taken.fetch_add(1, Ordering::Relaxed);
                i as f64
            },
        );
        assert_eq!(out.len(), 500);
        assert_eq!(taken.load(Ordering::Relaxed), 500);
        // Chunks written in place: every element once, by its own chunk's call.
        let mut filled = vec![0usize; 1003];
        fill_chunks(&mut filled, 10, |k, chunk| {
            for (j, x) in chunk.iter_mut().enumerate() {
                *x = 10 * k + j;
            }
        });
        assert!(filled.iter().enumerate().all(|(i, &x)| x == i));
        let mut moved = (0..300).map(|i| vec![i; 3]).collect::<Vec<_>>();
        let sums: Vec<AtomicUsize> = (0..300).map(|_| AtomicUsize::new(0)).collect();
        for_each_owned(std::mem::take(&mut moved), |i, v| {
            sums[i].store(v.iter().sum(), Ordering::Relaxed)
        });
        assert!(
            sums.iter()
                .enumerate()
                .all(|(i, s)| s.load(Ordering::Relaxed) == 3 * i)
        );
    }

    #[test]
    fn loops_on_helpers_give_the_same_bits_as_on_rayon() {
        let f = |i: usize| ((i as f64) * 0.37).sqrt().sin() * 1e3;
        let on_rayon: Vec<u64> = map(20_000, f).into_iter().map(f64::to_bits).collect();
        let helpers = SCOPED_HELPERS;
        let on_helpers: Vec<u64> = map_on_helpers(&helpers, 20_000, &|| (), &|_, i| f(i))
            .into_iter()
            .map(f64::to_bits)
            .collect();
        assert_eq!(on_rayon, on_helpers);
        // Strings (results with heap memory), each thread's scratch reused, counts that do
        // not divide into chunks.
        for count in [2, 3, 31, 1001] {
            let made = map_on_helpers(&helpers, count, &String::new, &|scratch, i| {
                scratch.clear();
                scratch.push_str(&i.to_string());
                scratch.clone()
            });
            assert_eq!(made, (0..count).map(|i| i.to_string()).collect::<Vec<_>>());
        }
        // Through this thread's helpers, nested loops included.
        let nested = with_helpers(SCOPED_HELPERS, || {
            assert_eq!(threads(), 4);
            map(100, |i| map(i, |j| j as u64).into_iter().sum::<u64>())
        });
        assert!(
            nested
                .iter()
                .enumerate()
                .all(|(i, &s)| s == (i * i.saturating_sub(1) / 2) as u64)
        );
        // Chunks written in place by the helpers, the last one short.
        let mut filled = vec![0u64; 10_007];
        with_helpers(SCOPED_HELPERS, || {
            fill_chunks(&mut filled, 16, |k, chunk| {
                for (j, x) in chunk.iter_mut().enumerate() {
                    *x = f(16 * k + j).to_bits();
                }
            })
        });
        assert_eq!(&filled[..], &map(10_007, |i| f(i).to_bits())[..]);
        // A panic in one index is reported on the calling thread.
        let caught = std::panic::catch_unwind(|| {
            map_on_helpers(&helpers, 100, &|| (), &|_, i| {
                assert!(i != 57, "index 57");
                i
            })
        });
        assert!(caught.is_err());
    }
}
