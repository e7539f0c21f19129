//! dEQP's command-line flags, taken out of `umbrage conform`'s arguments before clap sees them
//! (deqp-runner appends them after the suite's `deqp_args`, in the `--deqp-NAME=VALUE` form).

use std::ffi::OsString;
use std::path::PathBuf;

/// The dEQP flags of one `umbrage conform` invocation.
#[derive(Clone, Debug, Default)]
pub struct DeqpArgs {
    /// `--deqp-caselist-file=F`: one case name a line.
    pub caselist_file: Option<PathBuf>,
    /// `--deqp-case=P[,P...]`: names, `*` a wildcard.
    pub cases: Vec<String>,
    /// `--deqp-log-filename=F`: the QPA log (none when absent).
    pub log: Option<PathBuf>,
    /// `--deqp-log-flush=enable|disable`: flush the log after every case (enable, dEQP's default).
    pub log_flush: bool,
    /// `--deqp-shadercache-filename=F`: accepted; umbrage keeps no shader cache.
    pub shader_cache: Option<PathBuf>,
    /// `--deqp-vk-device-id=N`: the N-th physical device (1-based).
    pub device_id: Option<usize>,
    /// `--deqp-runmode=...`: `execute` (default) or `txt-caselist`.
    pub runmode: Option<String>,
    /// `--deqp-caselist-export-path=DIR`: where `txt-caselist` writes `umbrage-cases.txt`.
    pub export_path: Option<PathBuf>,
    /// Every other `--deqp-*` flag, ignored (dEQP's surface, watchdog, ... flags).
    pub ignored: Vec<String>,
    /// All of the dEQP flags as given (the log's `commandLineParameters`).
    pub command_line: String,
}

const TAKES_VALUE: [&str; 8] =
    ["caselist-file", "case", "log-filename", "log-flush", "shadercache-filename", "vk-device-id", "runmode", "caselist-export-path"];

/// Splits `argv` into what clap parses and the dEQP flags: `None` unless the subcommand is
/// `conform` and at least one `--deqp-*` flag is present. Errors name a malformed flag.
pub fn split(argv: Vec<OsString>) -> Result<(Vec<OsString>, Option<DeqpArgs>), String> {
    if argv.get(1).and_then(|a| a.to_str()) != Some("conform") || !argv.iter().any(|a| a.to_str().is_some_and(|s| s.starts_with("--deqp-")))
    {
        return Ok((argv, None));
    }
    let mut rest = Vec::new();
    let mut d = DeqpArgs { log_flush: true, ..Default::default() };
    let mut given = Vec::new();
    let mut it = argv.into_iter();
    while let Some(a) = it.next() {
        let Some(flag) = a.to_str().and_then(|s| s.strip_prefix("--deqp-")).map(str::to_string) else {
            rest.push(a);
            continue;
        };
        let (key, value) = match flag.split_once('=') {
            Some((k, v)) => (k.to_string(), Some(v.to_string())),
            None if TAKES_VALUE.contains(&flag.as_str()) => {
                let v = it.next().and_then(|v| v.into_string().ok()).ok_or_else(|| format!("--deqp-{flag} needs a value"))?;
                (flag.clone(), Some(v))
            }
            None => (flag.clone(), None),
        };
        given.push(match &value {
            Some(v) => format!("--deqp-{key}={v}"),
            None => format!("--deqp-{key}"),
        });
        let v = value.clone().unwrap_or_default();
        match key.as_str() {
            "caselist-file" => d.caselist_file = Some(PathBuf::from(v)),
            "case" => d.cases.extend(v.split(',').map(str::trim).filter(|p| !p.is_empty()).map(String::from)),
            "log-filename" => d.log = Some(PathBuf::from(v)),
            "log-flush" => {
                d.log_flush = match v.as_str() {
                    "enable" => true,
                    "disable" => false,
                    _ => return Err(format!("--deqp-log-flush: expected enable or disable, got '{v}'")),
                }
            }
            "shadercache-filename" => d.shader_cache = Some(PathBuf::from(v)),
            "vk-device-id" => {
                let n: usize = v.parse().map_err(|_| format!("--deqp-vk-device-id: expected a number from 1, got '{v}'"))?;
                if n == 0 {
                    return Err("--deqp-vk-device-id is 1-based: 0 names no device".into());
                }
                d.device_id = Some(n);
            }
            "runmode" => match v.as_str() {
                "execute" | "txt-caselist" => d.runmode = Some(v),
                _ => return Err(format!("--deqp-runmode: umbrage supports execute and txt-caselist, not '{v}'")),
            },
            "caselist-export-path" => d.export_path = Some(PathBuf::from(v)),
            _ => d.ignored.push(given.last().cloned().unwrap_or_default()),
        }
    }
    d.command_line = given.join(" ");
    Ok((rest, Some(d)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn os(v: &[&str]) -> Vec<OsString> {
        v.iter().map(OsString::from).collect()
    }

    #[test]
    fn takes_what_deqp_runner_appends() {
        let (rest, d) = split(os(&[
            "umbrage",
            "conform",
            "--timeout",
            "20",
            "--deqp-caselist-file=/o/c.txt",
            "--deqp-log-filename=/o/c.qpa",
            "--deqp-log-flush=disable",
            "--deqp-shadercache-filename=/o/t1.shader_cache",
            "--deqp-shadercache-truncate=disable",
            "--deqp-vk-device-id=2",
            "--deqp-case=umbrage.a.*,umbrage.b",
        ]))
        .unwrap();
        let d = d.unwrap();
        assert_eq!(rest, os(&["umbrage", "conform", "--timeout", "20"]));
        assert_eq!(d.caselist_file.as_deref(), Some(std::path::Path::new("/o/c.txt")));
        assert_eq!(d.log.as_deref(), Some(std::path::Path::new("/o/c.qpa")));
        assert!(!d.log_flush);
        assert_eq!(d.device_id, Some(2));
        assert_eq!(d.cases, ["umbrage.a.*", "umbrage.b"]);
        assert_eq!(d.ignored, ["--deqp-shadercache-truncate=disable"]);
    }

    #[test]
    fn leaves_other_commands_alone_and_refuses_bad_values() {
        let (rest, d) = split(os(&["umbrage", "render", "--deqp-case=x"])).unwrap();
        assert!(d.is_none());
        assert_eq!(rest.len(), 3);
        assert!(split(os(&["umbrage", "conform", "--deqp-vk-device-id=0"])).is_err());
        assert!(split(os(&["umbrage", "conform", "--deqp-vk-device-id=x"])).is_err());
        assert!(split(os(&["umbrage", "conform", "--deqp-runmode=xml-caselist"])).is_err());
        let (_, d) = split(os(&["umbrage", "conform", "--deqp-case", "umbrage.a"])).unwrap();
        assert_eq!(d.unwrap().cases, ["umbrage.a"]);
    }
}
