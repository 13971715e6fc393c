//! One benchmark run as a child process of the same `mpm` executable, so that its
//! wall time and peak memory are its own and a crash or runaway cannot take the
//! benchmark down. The child is reaped with wait4(2), which returns that child's
//! resource usage (ru_maxrss: its peak resident set, KiB on Linux). Its floor is
//! the parent's resident set at the fork (a few MiB).

use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// How the child ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exit {
    Code(i32),
    Signal(i32),
    /// Killed after the time limit.
    TimedOut,
}

#[derive(Clone, Copy, Debug)]
pub struct ChildRun {
    pub exit: Exit,
    /// From spawn to reaping (process start, set-up, run and outputs).
    pub wall_seconds: f64,
    /// Peak resident memory of the child in MiB.
    pub peak_mib: f64,
}

/// Run `exe args…` with stdout and stderr into `log_dir/{stdout,stderr}.txt`,
/// killing it after `timeout` seconds.
pub fn run_child(
    exe: &Path,
    args: &[String],
    log_dir: &Path,
    timeout: f64,
) -> std::io::Result<ChildRun> {
    let stdout = std::fs::File::create(log_dir.join("stdout.txt"))?;
    let stderr = std::fs::File::create(log_dir.join("stderr.txt"))?;
    let started = Instant::now();
    let mut command = Command::new(exe);
    command
        .args(args)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(stderr);
    // Force fork + exec. std otherwise uses vfork/posix_spawn, and with a shared
    // address space Linux charges the *parent's* lifetime peak RSS to the child's
    // ru_maxrss at exec (measured: every run of a bench whose parent had built a
    // 10⁵-particle model reported the same 63.8 MiB floor). After fork the child's
    // copy starts from the parent's current resident pages only (a few MiB).
    // SAFETY: the hook does nothing, so it is async-signal-safe.
    unsafe {
        command.pre_exec(|| Ok(()));
    }
    let mut child = command.spawn()?;
    let pid = child.id() as libc::pid_t;
    let mut timed_out = false;
    let mut pause = Duration::from_millis(1);
    let (status, usage) = loop {
        let flags = if timed_out { 0 } else { libc::WNOHANG };
        match wait4(pid, flags)? {
            Some(done) => break done,
            None if started.elapsed().as_secs_f64() > timeout => {
                child.kill()?;
                timed_out = true;
            }
            None => {
                std::thread::sleep(pause);
                pause = (pause * 2).min(Duration::from_millis(20));
            }
        }
    };
    let wall_seconds = started.elapsed().as_secs_f64();
    let exit = if timed_out {
        Exit::TimedOut
    } else if libc::WIFEXITED(status) {
        Exit::Code(libc::WEXITSTATUS(status))
    } else {
        Exit::Signal(libc::WTERMSIG(status))
    };
    Ok(ChildRun {
        exit,
        wall_seconds,
        peak_mib: usage.ru_maxrss as f64 / 1024.0,
    })
}

/// wait4 on one child: Some((status, usage)) once it has ended, None while it runs
/// (with WNOHANG).
fn wait4(pid: libc::pid_t, flags: i32) -> std::io::Result<Option<(i32, libc::rusage)>> {
    let mut status = 0;
    // SAFETY: rusage is plain data; wait4 fills it and the status for our own child.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    loop {
        let r = unsafe { libc::wait4(pid, &mut status, flags, &mut usage) };
        if r == pid {
            return Ok(Some((status, usage)));
        }
        if r == 0 {
            return Ok(None);
        }
        let e = std::io::Error::last_os_error();
        if e.kind() != std::io::ErrorKind::Interrupted {
            return Err(e);
        }
    }
}
