//! SIGINT and SIGTERM stop a run at the end of a step (issue 12, part 2): the
//! program writes its outputs so far, says `interrupted` in summary.json and exits
//! with 128 + the signal's number.

use crate::common::{problem, Table};
use mpm::run::summary::{Status, Summary};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Start `mpm run problems/collapse.toml` (15 s of work), send `signal` once it
/// has written a few history rows, and return its exit code and output directory.
fn interrupt(signal: i32) -> (Option<i32>, tempfile::TempDir) {
    interrupt_with(signal, &[])
}

/// `interrupt` with `--set` overrides.
fn interrupt_with(signal: i32, sets: &[&str]) -> (Option<i32>, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_mpm"))
        .arg("run")
        .arg(problem("collapse.toml"))
        .args(["--threads", "1", "--out"])
        .arg(dir.path())
        .args(sets.iter().flat_map(|s| ["--set", s]))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let history = dir.path().join("history.csv");
    let start = Instant::now();
    while std::fs::read_to_string(&history).map_or(0, |t| t.lines().count()) < 3 {
        assert!(start.elapsed() < Duration::from_secs(30), "no history rows");
        std::thread::sleep(Duration::from_millis(20));
    }
    // SAFETY: kill(2) on our own child's pid has no memory effects.
    assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
    let sent = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return (status.code(), dir);
        }
        assert!(
            sent.elapsed() < Duration::from_secs(20),
            "the run did not stop within 20 s of the signal"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn check_outputs(dir: &tempfile::TempDir, name: &str) {
    let s = Summary::read(&dir.path().join("summary.json")).unwrap();
    assert_eq!(s.status, Status::Interrupted);
    let m = s.message.unwrap();
    assert!(
        m.contains(&format!("interrupted by {name} at step {}", s.steps)),
        "{m}"
    );
    assert!(
        s.steps > 0 && s.end_time > 0.0 && s.end_time < 1.0,
        "t = {}",
        s.end_time
    );
    let particles = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    assert_eq!(particles.len(), s.particles);
    let history = Table::read(&dir.path().join("history.csv")).unwrap();
    assert_eq!(*history.col("t").last().unwrap(), s.end_time);
    let checkpoint = dir.path().join(format!("checkpoint_{:09}.json", s.steps));
    assert!(checkpoint.exists(), "{name} writes a checkpoint");
}

#[test]
fn sigint_stops_the_run_at_the_end_of_a_step_with_its_outputs() {
    let (code, dir) = interrupt(libc::SIGINT);
    assert_eq!(code, Some(130));
    check_outputs(&dir, "SIGINT");
}

#[test]
fn sigterm_stops_the_run_too_with_its_own_exit_code() {
    let (code, dir) = interrupt(libc::SIGTERM);
    assert_eq!(code, Some(143));
    check_outputs(&dir, "SIGTERM");
}

#[test]
fn an_interrupted_run_restarts_from_its_checkpoint_to_the_same_bytes() {
    // About 4 s of work on one thread (measured 1.0 s for 0.05 s of it on a
    // quiet machine). History rows reach the disk once a second
    // (`output::history`), so the run must outlast the first flush by a
    // margin, or it ends before the signal is sent.
    let sets = ["solver.end_time=0.2"];
    let (code, dir) = interrupt_with(libc::SIGINT, &sets);
    assert_eq!(code, Some(130));
    let s = Summary::read(&dir.path().join("summary.json")).unwrap();
    let checkpoint = dir.path().join(format!("checkpoint_{:09}.json", s.steps));
    assert!(checkpoint.exists(), "no checkpoint at step {}", s.steps);
    // Restart into the same directory, to the end.
    let restarted = Command::new(env!("CARGO_BIN_EXE_mpm"))
        .arg("run")
        .arg(problem("collapse.toml"))
        .args(["--threads", "1", "--set", sets[0], "--out"])
        .arg(dir.path())
        .arg("--restart")
        .arg(&checkpoint)
        .output()
        .unwrap();
    assert!(
        restarted.status.success(),
        "{}",
        String::from_utf8_lossy(&restarted.stderr)
    );
    let whole = crate::common::run_cli("collapse.toml", 1, &sets);
    let mut files = 0;
    for e in std::fs::read_dir(whole.path()).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().to_string();
        if name != "summary.json" {
            let a = std::fs::read(whole.path().join(&name)).unwrap();
            let b = std::fs::read(dir.path().join(&name)).unwrap();
            assert!(a == b, "{name} differs after the restart");
            files += 1;
        }
    }
    assert!(files >= 10, "{files} files compared");
    let s = Summary::read(&dir.path().join("summary.json")).unwrap();
    assert_eq!(s.status, Status::Completed);
    assert!(s.resumed_from.is_some());
}
