//! The `subd` command-line tool. All logic lives in the `subd_cli` library so that it can be
//! tested in-process; this wrapper only wires up the real stdout/stderr and the exit code.

fn main() {
    // Bad input is reported through typed errors; this hook only keeps an internal bug from
    // printing a backtrace at the user.
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        eprintln!("subd: internal error: {msg} (please report this)");
    }));
    // stderr stays unlocked between writes: the progress bar draws to it from its own thread.
    let stdout = std::io::stdout();
    let mut err = std::io::stderr();
    let code = {
        let mut out = stdout.lock();
        let code = subd_cli::run(std::env::args_os(), &mut out, &mut err);
        let _ = std::io::Write::flush(&mut out);
        code
    };
    std::process::exit(code);
}
