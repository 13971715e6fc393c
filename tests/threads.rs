//! Results do not depend on the number of threads: the same scene run with 1 and
//! 2 threads gives byte-identical outputs.

use std::process::Command;

fn run(threads: usize, shape: &str) -> (Vec<u8>, Vec<u8>) {
    let dir = tempfile::tempdir().unwrap();
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/problems/disks.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_mpm"))
        .args(["run", scene, "--threads", &threads.to_string(), "--out"])
        .arg(dir.path())
        .args(["--set", "solver.end_time=2.0", "--set", "output.frames=0"])
        .args(["--set", &format!("grid.shape_function={shape}")])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let read = |f: &str| std::fs::read(dir.path().join(f)).unwrap();
    (read("particles_final.csv"), read("history.csv"))
}

#[test]
fn one_and_two_threads_give_identical_results() {
    for shape in ["linear", "cpdi", "bspline2"] {
        let (p1, h1) = run(1, shape);
        let (p2, h2) = run(2, shape);
        assert!(
            p1 == p2,
            "{shape}: particles_final.csv differs between 1 and 2 threads"
        );
        assert!(
            h1 == h2,
            "{shape}: history.csv differs between 1 and 2 threads"
        );
    }
}
