//! The SIGINT flag of `recording::interrupt`, in a test binary of its own: a real SIGINT is
//! sent to the process, which must not race with other tests using the flag.

use armsim::core::interrupt;

#[test]
fn interrupt_flag_follows_sigint() {
    interrupt::install().unwrap();
    interrupt::install().unwrap(); // idempotent
    interrupt::reset();
    assert!(!interrupt::requested());
    let status = std::process::Command::new("kill")
        .args(["-INT", &std::process::id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    // Signal delivery is asynchronous: wait for it (bounded; not a timing assertion).
    for _ in 0..1000 {
        if interrupt::requested() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(interrupt::requested());
    interrupt::reset();
}
