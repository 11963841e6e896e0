//! /init of the emulated machine (see `emu/avx512`): runs the test binary `/simd`, waits for the
//! console to drain, then reports the exit status on a line of its own and stops.

use std::process::Command;
use std::time::Duration;

fn main() {
    let status = Command::new("/simd").status();
    // the console is a slow emulated UART: let the test output reach it before the report
    std::thread::sleep(Duration::from_secs(2));
    match status {
        Ok(s) => println!("\nRAYPIPE-EMU-EXIT {}", s.code().map_or("signal".to_string(), |c| c.to_string())),
        Err(e) => println!("\nRAYPIPE-EMU-EXIT cannot run /simd: {e}"),
    }
    std::thread::sleep(Duration::from_secs(2));
}
