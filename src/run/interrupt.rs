//! Stopping a run cleanly on SIGINT or SIGTERM: the signal only records itself;
//! the run looks at the record after every completed step (after a converged load
//! step, for the implicit solver), stops there, writes its outputs so far with
//! `status = "interrupted"` in summary.json, and `mpm run` exits with 128 + the
//! signal's number (130 for SIGINT, 143 for SIGTERM). A second SIGINT or SIGTERM
//! while the first is pending ends the program at once (exit code 1), for a run
//! whose step takes too long to wait for.
//!
//! The handlers come from the `signal-hook` crate, whose `flag` functions store
//! into an atomic and nothing else (what is safe inside a signal handler); writing
//! our own would need `unsafe` code with `libc::sigaction` for the same thing.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

/// The number of the signal received, 0 for none.
fn record() -> &'static Arc<AtomicUsize> {
    static RECEIVED: OnceLock<Arc<AtomicUsize>> = OnceLock::new();
    RECEIVED.get_or_init(|| Arc::new(AtomicUsize::new(0)))
}

/// Catch SIGINT and SIGTERM from now on (`mpm run` calls it once).
pub fn install() -> std::io::Result<()> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let received = record();
    // A pending signal and a second one: exit at once.
    let pending = Arc::new(std::sync::atomic::AtomicBool::new(false));
    for signal in [SIGINT, SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(signal, 1, pending.clone())?;
        signal_hook::flag::register(signal, pending.clone())?;
        signal_hook::flag::register_usize(signal, received.clone(), signal as usize)?;
    }
    Ok(())
}

/// The signal that asked the run to stop, if one did.
pub fn requested() -> Option<i32> {
    match record().load(Ordering::Relaxed) {
        0 => None,
        s => Some(s as i32),
    }
}

/// The signal's name, for messages.
pub fn name(signal: i32) -> &'static str {
    match signal {
        signal_hook::consts::SIGINT => "SIGINT",
        signal_hook::consts::SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn names() {
        assert_eq!(super::name(signal_hook::consts::SIGINT), "SIGINT");
        assert_eq!(super::name(signal_hook::consts::SIGTERM), "SIGTERM");
    }
}
