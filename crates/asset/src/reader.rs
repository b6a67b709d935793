//! Running usd-core and MaterialX: the reader script (`read_mtlx.py`, `shader_defs.py` and
//! `read_stage.py`, kept in this crate) under the Python interpreter that `$SPECCONV_USD_PYTHON` names (else
//! `python3`), bounded in time and output.

use crate::error::Error;
use crate::interpreter::{DEFAULT_TIMEOUT, PYTHON_VAR, TIMEOUT_VAR};
use crate::stage::Stage;
use std::ffi::{OsStr, OsString};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The reader script, run with `python -c`: the MaterialX half, the shader definitions, then
/// usd-core's half.
///
/// It starts by taking the current directory off the import path, where `python -c` puts it
/// first: a stray `json.py` or `pxr.py` in the directory `specconv asset` runs in would
/// otherwise be imported and run (issue 57, item 13). Not `-I`, which would also drop
/// `PYTHONPATH`, through which studios commonly reach their own USD build.
pub const SCRIPT: &str = concat!(
    "import sys\nif sys.path and sys.path[0] in ('', '.'):\n    del sys.path[0]\n",
    include_str!("read_mtlx.py"),
    include_str!("shader_defs.py"),
    include_str!("read_stage.py")
);

/// The most a reader may print: a stage's texture list is far smaller.
const MAX_OUTPUT: u64 = 256 << 20;

/// usd-core, through one Python interpreter.
#[derive(Debug, Clone)]
pub struct Reader {
    python: OsString,
    timeout: Duration,
}

impl Reader {
    /// The interpreter `$SPECCONV_USD_PYTHON` names, else `python3`; the time limit of
    /// `$SPECCONV_USD_TIMEOUT`, else [`DEFAULT_TIMEOUT`] seconds.
    pub fn from_env() -> Result<Reader, Error> {
        let python = std::env::var_os(PYTHON_VAR)
            .filter(|p| !p.is_empty())
            .unwrap_or_else(|| "python3".into());
        let timeout = match std::env::var(TIMEOUT_VAR) {
            Ok(t) if !t.trim().is_empty() => match t.trim().parse::<u64>() {
                Ok(s) if s > 0 => s,
                _ => return Err(Error::BadTimeout { value: t }),
            },
            _ => DEFAULT_TIMEOUT,
        };
        Ok(Reader::new(python, Duration::from_secs(timeout)))
    }

    /// usd-core through `python`, each run stopped after `timeout`.
    pub fn new(python: OsString, timeout: Duration) -> Reader {
        Reader { python, timeout }
    }

    /// The same, through another interpreter (the Python package's own).
    pub fn with_python(self, python: OsString) -> Reader {
        Reader { python, ..self }
    }

    /// The interpreter.
    pub fn python(&self) -> &OsStr {
        &self.python
    }

    /// Opens `stage` with composition and lists the textures its bound materials read; with
    /// `extract`, textures inside a usdz are copied out into its folder, replacing no file
    /// there but those it names (the files an asset run wrote, [`crate::record`]).
    pub fn read(&self, stage: &Path, extract: Option<(&Path, &[PathBuf])>) -> Result<Stage, Error> {
        let own = match extract {
            Some((_, own)) => {
                serde_json::to_string(own).map_err(|e| Error::Reader(e.to_string()))?
            }
            None => String::new(),
        };
        let mut args: Vec<&OsStr> = vec![OsStr::new("read"), stage.as_os_str()];
        if let Some((dir, _)) = extract {
            args.extend([dir.as_os_str(), OsStr::new(&own)]);
        }
        let out = self.run(&args, None)?;
        serde_json::from_slice(&out).map_err(|e| Error::Reader(format!("its answer: {e}")))
    }

    /// Writes the layer of overrides `plan` describes (a JSON object, see
    /// [`crate::plan::LayerPlan`]): usd-core makes its text, and it is written as every output
    /// is (`specconv_atomic_file`: a locked temporary beside it, renamed into place; the
    /// temporaries a killed run left beside it are removed first).
    ///
    /// The MaterialX override documents are written first, the USD layer (none for a
    /// document given alone) last; each file must be one the plan names.
    pub fn write_layer(&self, plan: &crate::plan::LayerPlan) -> Result<(), Error> {
        #[derive(serde::Deserialize)]
        struct File {
            path: std::path::PathBuf,
            text: String,
        }
        #[derive(serde::Deserialize)]
        struct Files {
            files: Vec<File>,
        }
        let json = serde_json::to_vec(plan).map_err(|e| Error::Reader(e.to_string()))?;
        let out = self.run(&[OsStr::new("layer")], Some(json))?;
        let files: Files =
            serde_json::from_slice(&out).map_err(|e| Error::Reader(format!("its answer: {e}")))?;
        let named = |p: &Path| p == plan.layer || plan.documents.iter().any(|d| d.layer == p);
        if let Some(f) = files.files.iter().find(|f| !named(&f.path)) {
            return Err(Error::Reader(format!(
                "it wrote {}, which the plan does not name",
                f.path.display()
            )));
        }
        for f in files.files {
            // Unchanged (`-u` on an asset whose textures did not change): left as it is, bytes
            // and mtime, so that what depends on it is not made out of date.
            if std::fs::read(&f.path).is_ok_and(|have| have == f.text.as_bytes()) {
                continue;
            }
            specconv_atomic_file::write(&f.path, f.text.as_bytes())
                .map_err(|e| Error::Io(f.path.clone(), e))?;
        }
        Ok(())
    }

    /// Runs the script with `args`, `stdin` written to it; its standard output, or the error
    /// it reported.
    fn run(&self, args: &[&OsStr], stdin: Option<Vec<u8>>) -> Result<Vec<u8>, Error> {
        let mut child = Command::new(&self.python)
            .arg("-c")
            .arg(SCRIPT)
            .args(args)
            .stdin(if stdin.is_some() {
                Stdio::piped()
            } else {
                Stdio::null()
            })
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|source| Error::NoPython {
                python: self.python.clone(),
                source,
            })?;
        if let (Some(mut pipe), Some(bytes)) = (child.stdin.take(), stdin) {
            std::thread::spawn(move || pipe.write_all(&bytes));
        }
        let take = |pipe: Option<Box<dyn Read + Send>>| {
            std::thread::spawn(move || {
                let mut buf = Vec::new();
                if let Some(p) = pipe {
                    let _ = p.take(MAX_OUTPUT + 1).read_to_end(&mut buf);
                }
                buf
            })
        };
        let out = take(child.stdout.take().map(|p| Box::new(p) as _));
        let err = take(child.stderr.take().map(|p| Box::new(p) as _));
        let start = Instant::now();
        let status = loop {
            if let Some(status) = child.try_wait().map_err(|e| Error::Reader(e.to_string()))? {
                break status;
            }
            if start.elapsed() > self.timeout {
                let _ = child.kill();
                let _ = child.wait();
                return Err(Error::Timeout {
                    seconds: self.timeout.as_secs(),
                });
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        let out = out.join().unwrap_or_default();
        let err = err.join().unwrap_or_default();
        if out.len() as u64 > MAX_OUTPUT {
            return Err(Error::Reader("it printed more than 256 MiB".into()));
        }
        if status.code() == Some(3) {
            return Err(Error::NoUsd {
                python: self.python.clone(),
            });
        }
        if status.code() == Some(4) {
            #[derive(serde::Deserialize)]
            struct Missing {
                detail: std::path::PathBuf,
            }
            let document = serde_json::from_slice::<Missing>(&out)
                .map(|m| m.detail)
                .unwrap_or_default();
            return Err(Error::NoMaterialX {
                python: self.python.clone(),
                document,
            });
        }
        if !status.success() && out.is_empty() && err.iter().all(u8::is_ascii_whitespace) {
            return Err(Error::Reader(format!(
                "'{}' exited with {status} and said nothing: name a Python 3 that has usd-core \
                 with {PYTHON_VAR}",
                self.python.to_string_lossy()
            )));
        }
        if !status.success() {
            return Err(reported(&out, &err));
        }
        Ok(out)
    }
}

/// The error the script reported (`{"error": kind, "detail": …}`), else its last lines.
fn reported(out: &[u8], err: &[u8]) -> Error {
    #[derive(serde::Deserialize)]
    struct Reported {
        error: String,
        detail: String,
    }
    match serde_json::from_slice::<Reported>(out) {
        Ok(r) if r.error == "open" => Error::Open {
            detail: clean(&r.detail),
        },
        Ok(r) if r.error == "mtlx" => Error::Document { detail: r.detail },
        Ok(r) if r.error == "not-ours" => Error::NotWrittenByAsset {
            path: r.detail.into(),
        },
        Ok(r) => Error::Reader(format!("{}: {}", r.error, clean(&r.detail))),
        Err(_) => {
            let text = String::from_utf8_lossy(err);
            let tail: Vec<&str> = text.lines().rev().take(3).collect();
            let tail: Vec<&str> = tail.into_iter().rev().collect();
            Error::Reader(tail.join(" / "))
        }
    }
}

/// usd-core's message without its C++ function names and source lines.
fn clean(detail: &str) -> String {
    detail
        .split(['\n', '\t'])
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .map(|l| match (l.find(" : '"), l.starts_with("Error in")) {
            (Some(i), true) => l[i + 3..].trim_end_matches('\'').to_owned(),
            _ => l.to_owned(),
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// Checks that `stage` can be given to the reader: a regular file (a FIFO would block it).
pub fn check_stage(stage: &Path) -> Result<(), Error> {
    let not = |why: String| Error::NotAStage {
        stage: stage.to_path_buf(),
        why,
    };
    let meta = std::fs::metadata(stage).map_err(|e| not(e.to_string()))?;
    if !meta.is_file() {
        return Err(not(
            "not a regular file (a FIFO, a device or a directory)".into()
        ));
    }
    Ok(())
}
