//! The `orbcloud` program: the process's setup, then the command line ([`orbcloud::cli`]).

use anyhow::Result;

fn main() -> Result<()> {
    // `orbcloud info FILE | head`: a closed output ends the command quietly, as it does any
    // Unix tool, instead of a panic at the next line printed.
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to its default before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // Mesa's device-select layer connects to a Wayland display to order the GPUs, and prints
    // "XDG_RUNTIME_DIR is invalid" twice where there is none (ssh, cron, CI); orbcloud chooses
    // its adapter itself.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() && std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: no other thread has started yet.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    orbcloud::cli::run(std::env::args_os().collect())
}
