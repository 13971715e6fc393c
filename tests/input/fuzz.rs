//! A seeded scene mutator over `problems/*.toml` (issue 12, part 6): each mutant
//! changes a value's type, removes a key, puts in an extreme value, resizes an
//! array, nests an expression deeply, adds an unknown key or passes a change as
//! a (possibly malformed) `--set` override. `mpm check` runs on every mutant and
//! a short `mpm run` on mutants of the small scenes; neither may panic, abort or
//! hang, and every error must name a key or the override it comes from. A process
//! still running after 20 s gets SIGTERM: a run that then stops at the end of its
//! step (exit 143) is slow, not hung; anything else is a failure.
//!
//! The suite runs a fixed seed (`fuzz_scenes`); `scripts/fuzz_campaign.sh` runs
//! the same mutator longer, on other seeds, through the ignored
//! `fuzz_campaign` test (`MPM_FUZZ_SEED`, `MPM_FUZZ_CHECKS`, `MPM_FUZZ_RUNS`).

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};
use toml_edit::{DocumentMut, Item, Value};

/// SplitMix64 (Steele, Lea and Flood 2014): a small deterministic generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// One step of a path into a TOML document: a key or an index.
#[derive(Clone, Debug)]
enum Seg {
    Key(String),
    Index(usize),
}

type KeyPath = Vec<Seg>;

fn dotted(path: &[Seg]) -> String {
    let parts: Vec<String> = path
        .iter()
        .map(|s| match s {
            Seg::Key(k) => k.clone(),
            Seg::Index(i) => i.to_string(),
        })
        .collect();
    parts.join(".")
}

/// Every value's path (arrays and their elements, scalars, inline tables) and
/// every table's path (for unknown keys).
fn paths(doc: &DocumentMut) -> (Vec<KeyPath>, Vec<KeyPath>) {
    fn item(it: &Item, at: KeyPath, values: &mut Vec<KeyPath>, tables: &mut Vec<KeyPath>) {
        match it {
            Item::Table(t) => {
                tables.push(at.clone());
                for (k, v) in t.iter() {
                    let mut p = at.clone();
                    p.push(Seg::Key(k.to_string()));
                    item(v, p, values, tables);
                }
            }
            Item::ArrayOfTables(a) => {
                for (i, t) in a.iter().enumerate() {
                    let mut p = at.clone();
                    p.push(Seg::Index(i));
                    tables.push(p.clone());
                    for (k, v) in t.iter() {
                        let mut q = p.clone();
                        q.push(Seg::Key(k.to_string()));
                        item(v, q, values, tables);
                    }
                }
            }
            Item::Value(v) => {
                values.push(at.clone());
                if let Value::Array(a) = v {
                    for i in 0..a.len() {
                        let mut p = at.clone();
                        p.push(Seg::Index(i));
                        values.push(p);
                    }
                }
            }
            Item::None => {}
        }
    }
    let (mut values, mut tables) = (Vec::new(), Vec::new());
    item(doc.as_item(), Vec::new(), &mut values, &mut tables);
    (values, tables)
}

/// The table or array that holds the last segment of a path.
enum Parent<'a> {
    Table(&'a mut dyn toml_edit::TableLike),
    Array(&'a mut toml_edit::Array),
}

fn parent<'a>(doc: &'a mut DocumentMut, path: &[Seg]) -> Option<Parent<'a>> {
    let mut cur = Parent::Table(doc.as_table_mut());
    let n = path.len().checked_sub(1)?;
    let mut i = 0;
    while i < n {
        cur = match (cur, &path[i]) {
            (Parent::Table(t), Seg::Key(k)) => match t.get_mut(k)? {
                Item::Table(t) => Parent::Table(t),
                Item::Value(Value::InlineTable(t)) => Parent::Table(t),
                Item::Value(Value::Array(a)) => Parent::Array(a),
                // An array of tables is entered with the next index of the path.
                Item::ArrayOfTables(a) => {
                    i += 1;
                    match path.get(i).filter(|_| i < n)? {
                        Seg::Index(j) => Parent::Table(a.get_mut(*j)?),
                        Seg::Key(_) => return None,
                    }
                }
                _ => return None,
            },
            (Parent::Array(a), Seg::Index(j)) => match a.get_mut(*j)? {
                Value::Array(b) => Parent::Array(b),
                Value::InlineTable(t) => Parent::Table(t),
                _ => return None,
            },
            _ => return None,
        };
        i += 1;
    }
    Some(cur)
}

/// Put `value` at `path` (None: remove it).
fn put(doc: &mut DocumentMut, path: &[Seg], value: Option<Value>) {
    let (Some(last), Some(p)) = (path.last().cloned(), parent(doc, path)) else {
        return;
    };
    match (p, last, value) {
        (Parent::Table(t), Seg::Key(k), Some(v)) => {
            t.insert(&k, Item::Value(v));
        }
        (Parent::Table(t), Seg::Key(k), None) => {
            t.remove(&k);
        }
        (Parent::Array(a), Seg::Index(i), Some(v)) if i < a.len() => {
            a.replace(i, v);
        }
        (Parent::Array(a), Seg::Index(i), None) if i < a.len() => {
            a.remove(i);
        }
        _ => {}
    }
}

/// Values of every kind and the extremes of numbers.
const VALUES: &[&str] = &[
    "\"text\"",
    "\"0.2\"",
    "true",
    "7",
    "-3",
    "0.5",
    "[1.0, 2.0]",
    "[]",
    "[[1.0]]",
    "{ a = 1 }",
    "0",
    "0.0",
    "-0.0",
    "5e-324",
    "1e-300",
    "1e300",
    "-1e300",
    "9223372036854775807",
    "-9223372036854775808",
    "-1",
    "nan",
    "inf",
    "-inf",
    "1e9",
    "4294967296",
    "[0.0, 0.0, 0.0]",
    "[1e300, 1e300]",
    "[5e-324, 5e-324]",
    "[100000, 100000]",
    "[100000, 100000, 100000]",
    "\"none\"",
    "\"cpdi\"",
    "\"\"",
];

/// The value at a path, if it is one.
fn value_at(doc: &DocumentMut, path: &[Seg]) -> Option<Value> {
    let mut doc = doc.clone();
    match (parent(&mut doc, path)?, path.last()?) {
        (Parent::Table(t), Seg::Key(k)) => t.get(k)?.as_value().cloned(),
        (Parent::Array(a), Seg::Index(i)) => a.get(*i).cloned(),
        _ => None,
    }
}

/// A number (or every number of an array) scaled by a power of ten or a half,
/// keeping its type; other values are replaced from `VALUES`.
fn scaled(v: Option<&Value>, rng: &mut Rng) -> String {
    let factor = *rng.pick(&[1e-3, 0.1, 0.5, 2.0, 10.0, 1e3]);
    let scale = |v: &Value| match v {
        Value::Float(x) => Some(toml_float(x.value() * factor)),
        Value::Integer(n) => Some(((*n.value() as f64 * factor).round() as i64).to_string()),
        _ => None,
    };
    match v {
        Some(Value::Array(a)) => {
            let items: Option<Vec<String>> = a.iter().map(scale).collect();
            items.map(|i| format!("[{}]", i.join(", ")))
        }
        Some(v) => scale(v),
        None => None,
    }
    .unwrap_or_else(|| rng.pick(VALUES).to_string())
}

/// A float as TOML writes it (`nan`, `inf`, `-inf` for the non-finite ones: an
/// earlier mutation may have left one to be scaled).
fn toml_float(x: f64) -> String {
    match x {
        x if x.is_nan() => "nan".into(),
        x if x.is_infinite() => if x > 0.0 { "inf" } else { "-inf" }.into(),
        x => format!("{x:e}"),
    }
}

/// An extreme value of the same type as `v` (numbers, arrays of numbers).
fn extreme(v: Option<&Value>, rng: &mut Rng) -> String {
    const FLOATS: &[&str] = &[
        "0.0", "-0.0", "5e-324", "1e-300", "1e-12", "1e12", "1e300", "-1e300", "nan", "inf",
        "-inf", "-1.0",
    ];
    const INTEGERS: &[&str] = &[
        "0",
        "-1",
        "1",
        "100000",
        "2147483648",
        "4611686018427387904",
        "9223372036854775807",
    ];
    match v {
        Some(Value::Float(_)) => rng.pick(FLOATS).to_string(),
        Some(Value::Integer(_)) => rng.pick(INTEGERS).to_string(),
        Some(Value::Boolean(b)) => (!*b.value()).to_string(),
        Some(Value::Array(a)) => {
            let pool = match a.get(0) {
                Some(Value::Integer(_)) => INTEGERS,
                _ => FLOATS,
            };
            let x = rng.pick(pool);
            let all: Vec<&str> = (0..a.len()).map(|_| *x).collect();
            format!("[{}]", all.join(", "))
        }
        _ => rng.pick(VALUES).to_string(),
    }
}

/// An expression nested `depth` deep.
fn nested(depth: usize) -> String {
    format!("\"{}x{}\"", "(".repeat(depth), ")".repeat(depth))
}

/// A mutant: the scene text and its overrides.
struct Mutant {
    text: String,
    overrides: Vec<String>,
    what: Vec<String>,
}

/// Keys that set how long a run takes: short runs leave them alone (`mpm check`
/// mutants change them; the step cap is tested there).
const DURATION_KEYS: &[&str] = &["end_time", "dt", "load_steps", "cfl"];

/// A mutant of `original` with `count` changes; `short` keeps runs short (no
/// change to the keys of `DURATION_KEYS`).
fn mutate(original: &str, rng: &mut Rng, count: usize, short: bool) -> Mutant {
    let mut doc: DocumentMut = original.parse().expect("shipped scenes parse");
    let mut overrides = Vec::new();
    let mut what = Vec::new();
    for _ in 0..count {
        let (mut values, tables) = paths(&doc);
        if short {
            values.retain(|p| {
                !p.iter()
                    .any(|s| matches!(s, Seg::Key(k) if DURATION_KEYS.contains(&k.as_str())))
            });
        }
        if values.is_empty() {
            break;
        }
        let path = rng.pick(&values).clone();
        let current = value_at(&doc, &path);
        let kind = rng.below(20);
        let text = match kind {
            // Short runs mostly get plausible values, so that most of them run.
            9.. if short => scaled(current.as_ref(), rng),
            0 => nested(1 + rng.below(20_000)),
            1 | 2 => "#remove".to_string(),
            3 => "#grow".to_string(),
            4 => "#unknown".to_string(),
            5..=8 => rng.pick(VALUES).to_string(),
            9..=13 => scaled(current.as_ref(), rng),
            _ => extreme(current.as_ref(), rng),
        };
        let as_override = rng.below(4) == 0;
        what.push(format!(
            "{}{} <- {}",
            if as_override { "--set " } else { "" },
            dotted(&path),
            if text.len() > 40 { &text[..40] } else { &text }
        ));
        if as_override {
            overrides.push(match rng.below(12) {
                0 => dotted(&path),
                1 => format!("={text}"),
                2 => format!("{}..x={text}", dotted(&path)),
                _ => format!("{}={}", dotted(&path), text.trim_start_matches('#')),
            });
            continue;
        }
        match text.as_str() {
            "#remove" => put(&mut doc, &path, None),
            "#grow" => {
                if let Some(Parent::Table(t)) = parent(&mut doc, &path) {
                    if let Some(Seg::Key(k)) = path.last() {
                        if let Some(Value::Array(a)) = t.get_mut(k).and_then(|i| i.as_value_mut()) {
                            match a.get(0).cloned() {
                                Some(v) => a.push_formatted(v),
                                None => a.push(1.0),
                            }
                        }
                    }
                }
            }
            "#unknown" => {
                let mut at = rng.pick(&tables).clone();
                at.push(Seg::Key("bogus_key".into()));
                if at.len() == 1 {
                    doc.as_table_mut().insert("bogus_key", toml_edit::value(1));
                } else {
                    put(&mut doc, &at, Some(Value::from(1)));
                }
            }
            v => put(&mut doc, &path, Some(v.parse().expect("pool values parse"))),
        }
    }
    Mutant {
        text: doc.to_string(),
        overrides,
        what,
    }
}

/// How one `mpm` process ended.
enum Ended {
    Exit(i32, String),
    Signal(String),
    /// Still running at the timeout, it stopped cleanly on SIGTERM.
    Interrupted,
    TimedOut,
}

fn mpm(args: &[OsString], timeout: Duration) -> Ended {
    let mut child = Command::new(env!("CARGO_BIN_EXE_mpm"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("mpm starts");
    // Read stderr while the child runs: a long message must not fill the pipe.
    let mut pipe = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut stderr = String::new();
        std::io::Read::read_to_string(&mut pipe, &mut stderr).ok();
        stderr
    });
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let stderr = reader.join().unwrap();
            return match status.code() {
                Some(c) => Ended::Exit(c, stderr),
                None => Ended::Signal(stderr),
            };
        }
        if start.elapsed() > timeout {
            // A run that is slow but not hung stops at the end of its step.
            // SAFETY: kill(2) on our own child's pid has no memory effects.
            unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
            let signalled = Instant::now();
            while signalled.elapsed() < Duration::from_secs(15) {
                if let Some(status) = child.try_wait().unwrap() {
                    reader.join().ok();
                    return match status.code() {
                        Some(143) => Ended::Interrupted,
                        _ => Ended::TimedOut,
                    };
                }
                std::thread::sleep(Duration::from_millis(5));
            }
            child.kill().ok();
            child.wait().ok();
            return Ended::TimedOut;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Judge one process: a clean exit (0 success, 1 a run that stopped early, 2 bad
/// input) and an error that names a key or an override. Returns a complaint.
fn judge(ended: Ended, ok_codes: &[i32]) -> Option<String> {
    match ended {
        Ended::Signal(e) => Some(format!("killed by a signal: {e}")),
        Ended::TimedOut => Some("timed out, and did not stop on SIGTERM".into()),
        Ended::Interrupted => None,
        Ended::Exit(c, e) if !ok_codes.contains(&c) => Some(format!("exit code {c}: {e}")),
        Ended::Exit(2, e) if !(e.contains("key `") || e.contains("override `--set")) => {
            Some(format!("error names no key: {e}"))
        }
        Ended::Exit(..) => None,
    }
}

fn problems() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        // limit-analysis scenes are another format (`mpm limit`).
        .filter(|p| {
            !p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("limit_")
        })
        .collect();
    v.sort();
    v
}

/// Scenes that run in well under a second: the short runs mutate these.
const SMALL: &[&str] = &[
    "column",
    "column_staged",
    "two_layer_column",
    "unconfined_compression",
    "vibrating_bar",
    "vibrating_bar_implicit",
    "wave_p",
    "disks",
];

/// Run `checks` mutants through `mpm check` and `runs` through `mpm run`, on two
/// threads; panics with every failing mutant.
fn campaign(seed: u64, checks: usize, runs: usize) {
    let scenes = problems();
    let dir = tempfile::tempdir().unwrap();
    let failures = Mutex::new(Vec::<String>::new());
    let next = AtomicUsize::new(0);
    // Exit codes 0, 1 and 2 and stops on SIGTERM, of the checks and of the runs.
    let counts: [[AtomicUsize; 4]; 2] = Default::default();
    let total = checks + runs;
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= total {
                    break;
                }
                let mut rng = Rng(seed ^ (i as u64).wrapping_mul(0x2545_f491_4f6c_dd1d));
                let run = i >= checks;
                let scene = if run {
                    let name = rng.pick(SMALL);
                    Path::new(env!("CARGO_MANIFEST_DIR"))
                        .join("problems")
                        .join(format!("{name}.toml"))
                } else {
                    rng.pick(&scenes).clone()
                };
                let original = std::fs::read_to_string(&scene).unwrap();
                let count = if run { 1 } else { 1 + rng.below(2) };
                let m = mutate(&original, &mut rng, count, run);
                let file = dir.path().join(format!("mutant{i}.toml"));
                std::fs::write(&file, &m.text).unwrap();
                let out = dir.path().join(format!("out{i}"));
                let mut args: Vec<OsString> = if run {
                    let out = out.clone().into_os_string();
                    // A small memory limit keeps the runs' grids and particle sets small.
                    vec![
                        "run".into(),
                        file.into(),
                        "--threads".into(),
                        "1".into(),
                        "--memory-limit".into(),
                        "0.05".into(),
                        "--out".into(),
                        out,
                    ]
                } else {
                    // Checks build the model: 1 GiB keeps that to a second or so.
                    vec![
                        "check".into(),
                        file.into(),
                        "--memory-limit".into(),
                        "1".into(),
                    ]
                };
                for o in &m.overrides {
                    args.extend(["--set".into(), o.into()]);
                }
                let ok: &[i32] = if run { &[0, 1, 2] } else { &[0, 2] };
                let timeout = Duration::from_secs(20);
                let ended = mpm(&args, timeout);
                if std::env::var_os("MPM_FUZZ_VERBOSE").is_some() {
                    if let Ended::Exit(c, e) = &ended {
                        eprintln!("mutant {i} ({}): exit {c} {e}", m.what.join("; "));
                    }
                }
                match &ended {
                    Ended::Exit(c @ 0..=2, _) => {
                        counts[run as usize][*c as usize].fetch_add(1, Ordering::Relaxed)
                    }
                    Ended::Interrupted => counts[run as usize][3].fetch_add(1, Ordering::Relaxed),
                    _ => 0,
                };
                if let Some(complaint) = judge(ended, ok) {
                    let name = scene.file_name().unwrap().to_string_lossy();
                    let failure =
                        format!("mutant {i} of {name} ({}): {complaint}", m.what.join("; "));
                    eprintln!("{failure}");
                    failures.lock().unwrap().push(failure);
                }
                std::fs::remove_dir_all(&out).ok();
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    let n = |r: usize, c: usize| counts[r][c].load(Ordering::Relaxed);
    println!(
        "fuzz seed {seed:#x}: {checks} checks ({} accepted, {} rejected naming a key), \
         {runs} runs ({} completed, {} stopped early, {} rejected naming a key, {} stopped \
         by SIGTERM after 20 s), {} failures",
        n(0, 0),
        n(0, 2),
        n(1, 0),
        n(1, 1),
        n(1, 2),
        n(1, 3),
        failures.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn fuzz_scenes() {
    campaign(0x5eed_0012, 400, 120);
}

/// The longer campaign of `scripts/fuzz_campaign.sh`.
#[test]
#[ignore]
fn fuzz_campaign() {
    let var = |k: &str, d: u64| {
        std::env::var(k)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(d)
    };
    campaign(
        var("MPM_FUZZ_SEED", 1),
        var("MPM_FUZZ_CHECKS", 5000) as usize,
        var("MPM_FUZZ_RUNS", 200) as usize,
    );
}

#[test]
fn the_mutator_is_deterministic_and_changes_the_scene() {
    let text = std::fs::read_to_string(&problems()[0]).unwrap();
    let a = mutate(&text, &mut Rng(7), 3, false);
    let b = mutate(&text, &mut Rng(7), 3, false);
    assert_eq!((&a.text, &a.overrides), (&b.text, &b.overrides));
    let changed = (0..50)
        .filter(|&s| {
            let m = mutate(&text, &mut Rng(s), 1, false);
            m.text != text || !m.overrides.is_empty()
        })
        .count();
    assert!(changed > 40, "only {changed} of 50 mutants differ");
}
