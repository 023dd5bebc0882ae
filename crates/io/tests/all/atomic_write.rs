//! `atomic_write`: what the written file looks like to everyone else.

/// Outputs get the permissions of a file any program creates (0666 less the umask), not
/// the owner-only mode of the temporary file they are written through.
#[cfg(target_os = "linux")]
#[test]
fn outputs_get_the_usual_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let umask = std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("Umask:"))
                .and_then(|l| u32::from_str_radix(l.split_whitespace().nth(1)?, 8).ok())
        })
        .unwrap_or(0o022);
    let dir = std::env::temp_dir().join(format!("subd-perm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("out.txt");
    subd_io::atomic_write(&path, |w| w.write_all(b"x\n")).unwrap();
    let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o666 & !umask, "mode {mode:o}, umask {umask:o}");
    std::fs::remove_dir_all(&dir).unwrap();
}
