//! The binary answers `--version` and `--help` with every command. Beyond checking that, this
//! integration test makes `cargo test` at the workspace root build the `umbrage` binary, which
//! the tests in the root's tests/ run as a process (tests/common/exe.rs).
use std::process::Command;

#[test]
fn help_lists_every_command_and_version_matches_the_crate() {
    let exe = env!("CARGO_BIN_EXE_umbrage");
    let help = Command::new(exe).arg("--help").output().expect("run umbrage --help");
    assert!(help.status.success(), "umbrage --help failed: {}", String::from_utf8_lossy(&help.stderr));
    let text = String::from_utf8_lossy(&help.stdout);
    for command in ["render", "view", "info", "check", "conform", "bench"] {
        assert!(text.lines().any(|l| l.trim_start().starts_with(command)), "`{command}` missing from --help:\n{text}");
    }
    let version = Command::new(exe).arg("--version").output().expect("run umbrage --version");
    assert!(version.status.success());
    assert_eq!(String::from_utf8_lossy(&version.stdout).trim(), format!("umbrage {}", env!("CARGO_PKG_VERSION")));
}

#[test]
fn an_unknown_command_fails_with_a_message() {
    let out = Command::new(env!("CARGO_BIN_EXE_umbrage")).arg("no-such-command").output().expect("run umbrage");
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no-such-command"));
}
