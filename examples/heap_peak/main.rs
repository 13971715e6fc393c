//! Which large heap arrays are live at the peak of an implicit step: a
//! counting allocator records every allocation of at least 1 MiB with its
//! call stack, and at the end prints the arrays live at the step's peak of
//! live heap, largest first. Then, per phase of the step (the call stack of
//! the latest large allocation), the highest live heap it reached: where the
//! peak would move if the top phase shrank. With HEAP_PEAK_PHASES set, also
//! the large arrays live at the end of each phase's highest visit and the highest resident
//! memory read at the phase's large allocations and frees (RSS can be far
//! below the live heap where an allocation is never touched).
//!
//! `cargo run --release --features probes --example heap_peak -- SCENE STEP [--set key=value ...]`

#[path = "../common/implicit_steps.rs"]
mod implicit_steps;

use implicit_steps::{scene_and_steps, steps, Moment};
use mpm::scene::Scene;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

const LARGE: usize = 1 << 20;

struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
static RECORD: AtomicBool = AtomicBool::new(false);
thread_local! { static INSIDE: Cell<bool> = const { Cell::new(false) }; }

struct Large {
    size: usize,
    stack: String,
}
static LIVE_LARGE: Mutex<Option<HashMap<usize, Large>>> = Mutex::new(None);
static AT_PEAK: Mutex<Vec<(usize, String)>> = Mutex::new(Vec::new());
/// Per phase (the call stack of the latest large allocation): the highest
/// live heap reached in it.
#[allow(clippy::type_complexity)]
static PHASES: Mutex<Option<HashMap<String, (usize, Vec<(usize, String)>)>>> = Mutex::new(None);
static PHASE: Mutex<String> = Mutex::new(String::new());
/// The highest live heap since the current phase began (updated on every
/// allocation without a lock; folded into PHASES when the phase ends).
static PHASE_TOP: AtomicUsize = AtomicUsize::new(0);
/// HEAP_PEAK_PHASES is set (read once, not inside the allocator).
static DETAILS: AtomicBool = AtomicBool::new(false);
/// Per phase: the highest resident memory read at its large allocations and
/// frees (/proc/self/statm, pages), with HEAP_PEAK_PHASES set.
static RSS_PHASES: Mutex<Option<HashMap<String, usize>>> = Mutex::new(None);

/// Resident pages now, read without allocating.
fn resident_pages() -> usize {
    use std::io::Read;
    let mut buf = [0u8; 128];
    let Ok(mut f) = std::fs::File::open("/proc/self/statm") else {
        return 0;
    };
    let n = f.read(&mut buf).unwrap_or(0);
    let text = std::str::from_utf8(&buf[..n]).unwrap_or("");
    text.split_whitespace()
        .nth(1)
        .and_then(|v| v.parse().ok())
        .unwrap_or(0)
}

fn note_rss() {
    if !DETAILS.load(Ordering::SeqCst) {
        return;
    }
    let phase = PHASE.lock().unwrap().clone();
    let pages = resident_pages();
    let mut m = RSS_PHASES.lock().unwrap();
    let top = m.get_or_insert_with(HashMap::new).entry(phase).or_default();
    *top = (*top).max(pages);
}

fn stack() -> String {
    let bt = std::backtrace::Backtrace::force_capture().to_string();
    bt.lines()
        .filter(|l| {
            (l.contains("mpm::") || l.contains("faer"))
                && !l.contains("heap_peak")
                && !l.contains("at /")
        })
        .map(|l| {
            l.trim()
                .trim_start_matches(|c: char| c.is_ascii_digit() || c == ':')
                .trim()
        })
        .take(4)
        .collect::<Vec<_>>()
        .join(" < ")
}

fn on_alloc(ptr: usize, size: usize) {
    let live = LIVE.fetch_add(size, Ordering::SeqCst) + size;
    if !RECORD.load(Ordering::SeqCst) {
        return;
    }
    INSIDE.with(|inside| {
        if inside.get() {
            return;
        }
        inside.set(true);
        if size >= LARGE {
            // A new phase: the previous one ends without this allocation.
            note_rss();
            let s = stack();
            end_phase();
            *PHASE.lock().unwrap() = s.clone();
            PHASE_TOP.store(live, Ordering::SeqCst);
            LIVE_LARGE
                .lock()
                .unwrap()
                .get_or_insert_with(HashMap::new)
                .insert(ptr, Large { size, stack: s });
        } else {
            PHASE_TOP.fetch_max(live, Ordering::SeqCst);
        }
        if live > PEAK.load(Ordering::SeqCst) {
            PEAK.store(live, Ordering::SeqCst);
            if size >= LARGE {
                *AT_PEAK.lock().unwrap() = snapshot();
            }
        }
        inside.set(false);
    });
}

/// Fold the current phase's highest live heap into PHASES (with the large
/// arrays live now, at its end, when HEAP_PEAK_PHASES is set: its only large
/// allocation is the one that began it).
fn end_phase() {
    let phase = PHASE.lock().unwrap().clone();
    let top = PHASE_TOP.load(Ordering::SeqCst);
    let mut phases = PHASES.lock().unwrap();
    let Some(phases) = phases.as_mut() else {
        return;
    };
    let entry = phases.entry(phase).or_default();
    if top > entry.0 {
        entry.0 = top;
        if DETAILS.load(Ordering::SeqCst) {
            entry.1 = snapshot();
        }
    }
}

/// The large arrays live now.
fn snapshot() -> Vec<(usize, String)> {
    LIVE_LARGE
        .lock()
        .unwrap()
        .as_ref()
        .map(|m| m.values().map(|l| (l.size, l.stack.clone())).collect())
        .unwrap_or_default()
}

fn on_free(ptr: usize, size: usize) {
    LIVE.fetch_sub(size, Ordering::SeqCst);
    if size >= LARGE && RECORD.load(Ordering::SeqCst) {
        INSIDE.with(|inside| {
            if inside.get() {
                return;
            }
            inside.set(true);
            note_rss();
            if let Some(m) = LIVE_LARGE.lock().unwrap().as_mut() {
                m.remove(&ptr);
            }
            inside.set(false);
        });
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc(layout);
        on_alloc(p as usize, layout.size());
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        on_free(p as usize, layout.size());
        System.dealloc(p, layout)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc_zeroed(layout);
        on_alloc(p as usize, layout.size());
        p
    }
    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new: usize) -> *mut u8 {
        on_free(p as usize, layout.size());
        let q = System.realloc(p, layout, new);
        on_alloc(q as usize, new);
        q
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn run<const D: usize>(scene: &Scene, step_of_interest: usize) {
    let details = std::env::var_os("HEAP_PEAK_PHASES").is_some();
    DETAILS.store(details, Ordering::SeqCst);
    let mut model_bytes = 0;
    steps::<D>(scene, step_of_interest, |moment| match moment {
        Moment::Built => {
            model_bytes = LIVE.load(Ordering::SeqCst);
            RECORD.store(true, Ordering::SeqCst);
        }
        Moment::Before(step) if step == step_of_interest => {
            PEAK.store(LIVE.load(Ordering::SeqCst), Ordering::SeqCst);
            *PHASES.lock().unwrap() = Some(HashMap::new());
            PHASE_TOP.store(LIVE.load(Ordering::SeqCst), Ordering::SeqCst);
            *RSS_PHASES.lock().unwrap() = Some(HashMap::new());
        }
        _ => {}
    });
    RECORD.store(false, Ordering::SeqCst);
    end_phase();
    let mib = |b: usize| b as f64 / (1 << 20) as f64;
    let peak = PEAK.load(Ordering::SeqCst);
    println!(
        "model {:.1} MiB; step {step_of_interest} live-heap peak {:.1} MiB, solver {:.1} MiB",
        mib(model_bytes),
        mib(peak),
        mib(peak - model_bytes)
    );
    print_arrays(&AT_PEAK.lock().unwrap());
    // The highest live heap of each phase (after each large allocation's
    // call stack), highest first: where the peak would move if the top
    // phase shrank. With HEAP_PEAK_PHASES set, the arrays live at each.
    let mut phases: Vec<_> = PHASES
        .lock()
        .unwrap()
        .take()
        .unwrap_or_default()
        .into_iter()
        .collect();
    phases.sort_by_key(|p| std::cmp::Reverse(p.1 .0));
    let mut rss: Vec<_> = (RSS_PHASES
        .lock()
        .unwrap()
        .take()
        .unwrap_or_default()
        .into_iter())
    .collect();
    rss.sort_by_key(|p| std::cmp::Reverse(p.1));
    if !rss.is_empty() {
        println!("highest resident memory per phase (read at large allocations and frees):");
        for (s, pages) in rss.iter().take(12) {
            println!("{:9.1} MiB  {s}", *pages as f64 * 4096.0 / 1048576.0);
        }
    }
    println!("highest live heap per phase (after the large allocation of):");
    for (s, (top, arrays)) in phases.iter().take(12) {
        println!("{:9.1} MiB  {s}", mib(top - model_bytes));
        print_arrays(arrays);
    }
}

/// Arrays grouped by call stack and size, largest first.
fn print_arrays(arrays: &[(usize, String)]) {
    let mib = |b: usize| b as f64 / (1 << 20) as f64;
    let mut groups: HashMap<String, (usize, usize)> = HashMap::new();
    for (size, s) in arrays {
        let g = groups
            .entry(format!("{s} [{:.1}]", mib(*size)))
            .or_default();
        g.0 += size;
        g.1 += 1;
    }
    let mut rows: Vec<_> = groups.into_iter().collect();
    rows.sort_by_key(|r| std::cmp::Reverse(r.1 .0));
    for (s, (size, n)) in rows {
        println!("{:9.1} MiB {n:4}x  {s}", mib(size));
    }
}

fn main() {
    let (scene, step) = scene_and_steps("heap_peak SCENE STEP [--set k=v ...]", 1);
    match scene.config.dimension.spatial() {
        3 => run::<3>(&scene, step),
        _ => run::<2>(&scene, step),
    }
}
