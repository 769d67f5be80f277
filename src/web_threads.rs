//! Every core in the page: the threaded bundle's Web Workers.
//!
//! Built with WebAssembly atomics (`web/build.sh` makes `web/pkg-threads` beside the
//! single-threaded `web/pkg`), the module's memory is shared, and `startThreads(n)` starts n - 1
//! helper threads, each a Web Worker instantiating this module on that memory
//! (`web/threads.js`), and installs them as the kernel's [`knotwork_kernel::par::Helpers`]. A
//! parallel loop entered on the page's main thread then runs there and on every helper at
//! once, each claiming chunks of indices until none are left.
//!
//! The browser's main thread may not wait (`Atomics.wait` is refused there), so it never takes
//! a lock a helper could hold: it publishes the loop's work through atomics, wakes the helpers
//! (`unpark` does not wait), works itself, then closes the loop and spins only while helpers
//! that joined it finish their chunks. A helper that wakes after the loop is closed does not
//! join it, so the main thread never waits for a helper to wake. Helpers wait for work parked,
//! which a worker may.
//!
//! The page uses this bundle only where it is cross-origin isolated (shared memory needs the
//! COOP/COEP headers `web/server.mjs` sends); elsewhere it loads the single-threaded bundle,
//! where the same loops run on the main thread with the same results.

use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock, PoisonError};
use std::thread::Thread;

use wasm_bindgen::prelude::*;
use wasm_bindgen_futures::JsFuture;

#[wasm_bindgen(module = "/web/threads.js")]
extern "C" {
    /// Starts a Web Worker on this module and memory running the thread `entry`.
    #[wasm_bindgen(js_name = spawnThread)]
    fn spawn_thread(module: JsValue, memory: JsValue, entry: usize) -> js_sys::Promise;
}

thread_local! {
    /// Whether this thread is inside a loop's work (a helper always is): a loop met there
    /// runs on this thread alone.
    static INSIDE: Cell<bool> = const { Cell::new(false) };
}

/// What a worker runs.
type Entry = Box<dyn FnOnce() + Send>;

/// The loop the helpers are asked to join: its work, on the main thread's stack.
struct Job {
    work: *const (dyn Fn() + Sync),
}

/// The current job (null between loops).
static JOB: AtomicPtr<Job> = AtomicPtr::new(std::ptr::null_mut());
/// Bumped for every job: a helper looks at each generation once.
static GENERATION: AtomicUsize = AtomicUsize::new(0);
/// Whether the current job may still be joined.
static OPEN: AtomicBool = AtomicBool::new(false);
/// Helpers inside a job (or about to see that it is closed). A helper counts itself in before
/// it reads `OPEN`, and the main thread closes the job before it waits for this to reach zero
/// (both sequentially consistent): either the main thread waits for the helper, or the helper
/// sees the job closed.
static ACTIVE: AtomicUsize = AtomicUsize::new(0);
/// Set by the panic hook when any thread panics: a helper's panic aborts that worker, and the
/// main thread, spinning for its loop, would otherwise wait for ever.
static PANICKED: AtomicBool = AtomicBool::new(false);
/// The helpers as they start (only helpers lock it; the main thread takes the list once all
/// have registered, when no helper holds the lock any more).
static STARTING: Mutex<Vec<Thread>> = Mutex::new(Vec::new());
static STARTED: AtomicUsize = AtomicUsize::new(0);
/// The helpers, once all have started.
static HELPER_THREADS: OnceLock<Vec<Thread>> = OnceLock::new();

/// Starts a worker running `entry`; resolves when it is about to run it.
fn spawn(entry: Entry) -> js_sys::Promise {
    let entry = Box::into_raw(Box::new(entry)) as usize;
    spawn_thread(wasm_bindgen::module(), wasm_bindgen::memory(), entry)
}

/// A worker's start (called by `web/threads.js` in the worker, with the pointer [`spawn`]
/// made): runs the thread to its end.
#[wasm_bindgen(js_name = knotworkThreadEntry)]
pub fn thread_entry(entry: usize) {
    // SAFETY: `entry` is the pointer `spawn` made from a box for this worker alone; the page
    // passes it through unchanged, once.
    let entry = unsafe { Box::from_raw(entry as *mut Entry) };
    entry();
}

/// A helper: registers, then joins each job once, parked in between.
fn helper() {
    INSIDE.with(|inside| inside.set(true));
    // Read before registering: no job starts before every helper has registered.
    let mut seen = GENERATION.load(Ordering::SeqCst);
    STARTING
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .push(std::thread::current());
    STARTED.fetch_add(1, Ordering::Release);
    loop {
        let generation = GENERATION.load(Ordering::SeqCst);
        if generation == seen {
            std::thread::park();
            continue;
        }
        seen = generation;
        ACTIVE.fetch_add(1, Ordering::SeqCst);
        if OPEN.load(Ordering::SeqCst) {
            let job = JOB.load(Ordering::SeqCst);
            // SAFETY: the job is open and this helper is counted in ACTIVE: the main thread
            // keeps the job and its work alive until ACTIVE is back at zero.
            if let Some(job) = unsafe { job.as_ref() } {
                unsafe { (*job.work)() };
            }
        }
        ACTIVE.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The kernel's [`knotwork_kernel::par::Helpers::run`]: `work` here and on every helper.
fn run_everywhere(work: &(dyn Fn() + Sync)) {
    let helpers = match HELPER_THREADS.get() {
        Some(helpers) if !INSIDE.with(Cell::get) => helpers,
        _ => return work(),
    };
    let work: *const (dyn Fn() + Sync + '_) = work;
    // SAFETY: only the lifetime is erased; this function does not return before every helper
    // inside the job has left it (ACTIVE back at zero, the job closed).
    let work: *const (dyn Fn() + Sync + 'static) = unsafe { std::mem::transmute(work) };
    let job = Job { work };
    JOB.store(&job as *const Job as *mut Job, Ordering::SeqCst);
    OPEN.store(true, Ordering::SeqCst);
    GENERATION.fetch_add(1, Ordering::SeqCst);
    for helper in helpers {
        helper.unpark();
    }
    INSIDE.with(|inside| inside.set(true));
    // SAFETY: `job.work` is `work`, alive for this call.
    unsafe { (*job.work)() };
    INSIDE.with(|inside| inside.set(false));
    // Every index is claimed: helpers still asleep need not join. Wait for those inside.
    OPEN.store(false, Ordering::SeqCst);
    while ACTIVE.load(Ordering::SeqCst) != 0 {
        if PANICKED.load(Ordering::Relaxed) {
            panic!("a worker thread of the page panicked (see the console)");
        }
        std::hint::spin_loop();
    }
    JOB.store(std::ptr::null_mut(), Ordering::SeqCst);
}

/// `startThreads(count)`: makes the kernel's loops run on `count` threads, the page's main
/// thread and `count - 1` helper Web Workers. Resolves to the number of threads. Call it once,
/// before the editor starts.
#[wasm_bindgen(js_name = startThreads)]
pub async fn start_threads(count: usize) -> Result<usize, JsValue> {
    let helpers = count.clamp(1, 64) - 1;
    if helpers == 0 || HELPER_THREADS.get().is_some() {
        return Ok(knotwork_kernel::par::threads());
    }
    let previous_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        PANICKED.store(true, Ordering::Relaxed);
        previous_hook(info);
    }));
    let started: Vec<js_sys::Promise> = (0..helpers).map(|_| spawn(Box::new(helper))).collect();
    for promise in started {
        JsFuture::from(promise).await?;
    }
    // Each helper announced itself just before it ran: wait (spinning, a few milliseconds at
    // most) until all have registered and let go of the list.
    let since = js_sys::Date::now();
    while STARTED.load(Ordering::Acquire) < helpers {
        if js_sys::Date::now() - since > 10_000.0 {
            return Err(JsValue::from_str("the page's helper threads did not start"));
        }
        std::hint::spin_loop();
    }
    let threads = std::mem::take(&mut *STARTING.lock().unwrap_or_else(PoisonError::into_inner));
    let _ = HELPER_THREADS.set(threads);
    knotwork_kernel::par::set_helpers(knotwork_kernel::par::Helpers {
        run: run_everywhere,
        threads: helpers + 1,
    });
    Ok(knotwork_kernel::par::threads())
}
