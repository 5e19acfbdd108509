//! `simulate` writes its frames as they are solved: memory stays flat
//! however many steps a run has. The child's peak resident size is read
//! from the kernel (wait4), not estimated.

use std::io::Read;
use std::path::PathBuf;
use std::process::{Command, Stdio};

fn mechanism(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../mechanisms")
        .join(path)
}

/// Runs dofplan with `args`; its standard output's length and last bytes,
/// and its peak resident size in KiB.
// The child is reaped by wait4 below, which std's `wait` cannot replace:
// it is what returns the peak memory.
#[allow(clippy::zombie_processes)]
fn run(args: &[&str]) -> (usize, Vec<u8>, i64) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_dofplan"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("the dofplan binary runs");
    let mut stdout = child.stdout.take().expect("piped");
    // Read as it comes and keep only the tail: the test itself must not
    // hold the output either.
    let (mut total, mut tail) = (0, Vec::new());
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = stdout.read(&mut buf).expect("reads");
        if n == 0 {
            break;
        }
        total += n;
        tail.extend_from_slice(&buf[..n]);
        if tail.len() > 64 {
            tail.drain(..tail.len() - 64);
        }
    }
    let mut status = 0;
    // SAFETY: an all-zero rusage is a valid value for the kernel to fill.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: the child is ours and not yet waited for (std's `Child` was
    // not waited on); the pointers are to live locals.
    let pid = unsafe { libc::wait4(child.id() as libc::pid_t, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as libc::pid_t, "wait4");
    assert!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "dofplan {args:?} failed"
    );
    (total, tail, usage.ru_maxrss)
}

#[test]
fn a_long_sweep_streams_in_flat_memory() {
    let file = mechanism("stress_50.toml");
    let file = file.to_str().unwrap();
    // 5,000 frames of 50 four-bar loops: 55 MB of JSON. Kept in memory as
    // a document it would take several times that; streamed, the process
    // stays near its size at rest.
    let (bytes, tail, peak_kib) = run(&["simulate", file, "--steps", "5000", "--json"]);
    assert!(bytes > 50_000_000, "{bytes} bytes of JSON");
    assert!(
        String::from_utf8_lossy(&tail).ends_with("  ]\n}\n"),
        "the document is closed"
    );
    assert!(peak_kib < 48 * 1024, "simulate --json peaked at {peak_kib} KiB");
    let (bytes, _, peak_kib) = run(&["simulate", file, "--steps", "5000", "--csv"]);
    assert!(bytes > 30_000_000, "{bytes} bytes of CSV");
    assert!(peak_kib < 48 * 1024, "simulate --csv peaked at {peak_kib} KiB");
    // A spatial sweep streams too.
    let file = mechanism("spatial/spatial_stress_10.toml");
    let (bytes, tail, peak_kib) = run(&["simulate", file.to_str().unwrap(), "--steps", "5000", "--json"]);
    assert!(bytes > 10_000_000, "{bytes} bytes of spatial JSON");
    assert!(
        String::from_utf8_lossy(&tail).ends_with("}\n"),
        "the document is closed"
    );
    assert!(
        peak_kib < 48 * 1024,
        "spatial simulate --json peaked at {peak_kib} KiB"
    );
}
