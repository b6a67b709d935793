//! Running usd-core and MaterialX: the asset reader, the Python package
//! `specconv._asset_reader` (python/specconv/_asset_reader), asked one request and giving one
//! answer in its protocol (a JSON object each, `protocol` their version), carried one of two
//! ways: a child `python -I` of the interpreter `$SPECCONV_USD_PYTHON` names (else `python3`),
//! bounded in time and output (the command line), or a call into the interpreter the Python
//! package runs in ([`Reader::in_process`]). One parser reads the answers of both.

use crate::error::Error;
use crate::interpreter::{DEFAULT_TIMEOUT, PROTOCOL, PYTHON_VAR, TIMEOUT_VAR};
use crate::stage::Stage;
use serde_json::{json, Value};
use std::ffi::{OsStr, OsString};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The reader's modules, built into the program (one copy, the package's own), imported by
/// [`BOOTSTRAP`] from these strings.
const MODULES: [(&str, &str); 5] = [
    (
        "__init__",
        include_str!("../../../python/specconv/_asset_reader/__init__.py"),
    ),
    (
        "protocol",
        include_str!("../../../python/specconv/_asset_reader/protocol.py"),
    ),
    (
        "shader_defs",
        include_str!("../../../python/specconv/_asset_reader/shader_defs.py"),
    ),
    (
        "mtlx",
        include_str!("../../../python/specconv/_asset_reader/mtlx.py"),
    ),
    (
        "stage",
        include_str!("../../../python/specconv/_asset_reader/stage.py"),
    ),
];

/// Run with `python -I -c`, the modules as `NAME SOURCE` arguments: it loads them without a
/// file on disk and answers the request on standard input. `-I` keeps the working directory
/// off the import path, where a stray `json.py` or `pxr.py` would be imported and run (issue
/// 57, item 13; issue 58, item 5), and the user's site-packages and `PYTHON*` variables with
/// it; the bootstrap puts back the absolute folders of `PYTHONPATH`, through which studios
/// reach their own USD build (docs/assets.md, "How it runs").
const BOOTSTRAP: &str = include_str!("../../../python/specconv/_asset_reader/bootstrap.py");

/// The most a reader may print: a stage's texture list is far smaller.
const MAX_OUTPUT: u64 = 256 << 20;

/// A call into an interpreter that has imported the reader: its `answer(request)`, the
/// status and the answer's text; `Err`, what Python raised.
pub type Call = Arc<dyn Fn(&str) -> Result<(i32, String), String> + Send + Sync>;

/// What a carrier brings back: the reader's status, its answer's text, what else it said.
type Brought = (Option<i32>, Vec<u8>, Vec<u8>);

/// How a request reaches the reader.
#[derive(Clone)]
enum Carrier {
    /// A child `python -I`, stopped after this long.
    Child(Duration),
    /// A call into the interpreter the Python package runs in (no time limit: it is the
    /// caller's own).
    Call(Call),
}

/// usd-core, through one Python interpreter.
#[derive(Clone)]
pub struct Reader {
    python: OsString,
    carrier: Carrier,
}

impl std::fmt::Debug for Reader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let carrier = match &self.carrier {
            Carrier::Child(timeout) => format!("child, {} s", timeout.as_secs()),
            Carrier::Call(_) => "in process".to_owned(),
        };
        f.debug_struct("Reader")
            .field("python", &self.python)
            .field("carrier", &carrier)
            .finish()
    }
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

    /// usd-core through a child `python`, each run stopped after `timeout`.
    pub fn new(python: OsString, timeout: Duration) -> Reader {
        Reader {
            python,
            carrier: Carrier::Child(timeout),
        }
    }

    /// usd-core in the interpreter the caller runs in (`python`, named in messages), asked
    /// through `call` (the Python package's: `specconv._asset_reader.answer`).
    pub fn in_process(python: OsString, call: Call) -> Reader {
        Reader {
            python,
            carrier: Carrier::Call(call),
        }
    }

    /// The interpreter.
    pub fn python(&self) -> &OsStr {
        &self.python
    }

    /// Opens `stage` with composition and lists the textures its bound materials read; with
    /// `extract`, textures inside a usdz are copied out into its folder, replacing no file
    /// there but those it names (the files an asset run wrote, [`crate::record`]).
    pub fn read(&self, stage: &Path, extract: Option<(&Path, &[PathBuf])>) -> Result<Stage, Error> {
        let extract = extract.map(|(dir, own)| json!({"dir": dir, "replaceable": own}));
        let answer = self.ask(json!({"command": "read", "stage": stage, "extract": extract}))?;
        serde_json::from_value(answer).map_err(|e| Error::Reader(format!("its answer: {e}")))
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
        let plan_json = serde_json::to_value(plan).map_err(|e| Error::Reader(e.to_string()))?;
        let answer = self.ask(json!({"command": "layer", "plan": plan_json}))?;
        let files: Files = serde_json::from_value(answer)
            .map_err(|e| Error::Reader(format!("its answer: {e}")))?;
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

    /// The reader's answer to `request` (its protocol's version added), by either carrier.
    fn ask(&self, mut request: Value) -> Result<Value, Error> {
        request["protocol"] = PROTOCOL.into();
        let request = serde_json::to_string(&request)
            .map_err(|e| Error::Reader(format!("its request: {e}")))?;
        let (status, out, err) = match &self.carrier {
            Carrier::Child(timeout) => self.run(request.into_bytes(), *timeout)?,
            Carrier::Call(call) => {
                let (status, out) = call(&request).map_err(Error::Reader)?;
                (Some(status), out.into_bytes(), Vec::new())
            }
        };
        answer(&self.python, status, &out, &err)
    }

    /// Runs the reader in a child `python -I`, `request` on its standard input: its exit
    /// status, standard output and error; the errors only a child has (it did not start, did
    /// not end in time, printed too much, or failed without a word).
    fn run(&self, request: Vec<u8>, timeout: Duration) -> Result<Brought, Error> {
        let mut child = Command::new(&self.python)
            .args(["-I", "-c", BOOTSTRAP])
            .args(MODULES.iter().flat_map(|(name, source)| [name, source]))
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|source| Error::NoPython {
                python: self.python.clone(),
                source,
            })?;
        if let Some(mut pipe) = child.stdin.take() {
            std::thread::spawn(move || pipe.write_all(&request));
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
            if start.elapsed() > timeout {
                let _ = child.kill();
                let _ = child.wait();
                return Err(Error::Timeout {
                    seconds: timeout.as_secs(),
                });
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        let out = out.join().unwrap_or_default();
        let err = err.join().unwrap_or_default();
        if out.len() as u64 > MAX_OUTPUT {
            return Err(Error::Reader("it printed more than 256 MiB".into()));
        }
        if !status.success() && out.is_empty() && err.iter().all(u8::is_ascii_whitespace) {
            return Err(Error::Reader(format!(
                "'{}' exited with {status} and said nothing: name a Python 3 that has usd-core \
                 with {PYTHON_VAR}",
                self.python.to_string_lossy()
            )));
        }
        Ok((status.code(), out, err))
    }
}

/// The reader's answer, whichever carrier brought it (`status` the reader's, `out` its
/// answer's text, `err` what else it said): the answer if it is one of [`PROTOCOL`], else
/// the error it reported or why it is none.
fn answer(python: &OsStr, status: Option<i32>, out: &[u8], err: &[u8]) -> Result<Value, Error> {
    let parsed = serde_json::from_slice::<Value>(out);
    if let Ok(Value::Object(object)) = &parsed {
        let found = object.get("protocol");
        if found.and_then(Value::as_u64) != Some(PROTOCOL) {
            return Err(Error::Protocol {
                python: python.to_owned(),
                found: found.map(Value::to_string),
            });
        }
    }
    match status {
        Some(0) => parsed.map_err(|e| Error::Reader(format!("its answer: {e}"))),
        Some(3) => Err(Error::NoUsd {
            python: python.to_owned(),
        }),
        Some(4) => {
            let detail = parsed.ok().and_then(|a| a.get("detail").cloned());
            let document = detail.and_then(|d| d.as_str().map(PathBuf::from));
            Err(Error::NoMaterialX {
                python: python.to_owned(),
                document: document.unwrap_or_default(),
            })
        }
        _ => Err(reported(out, err)),
    }
}

/// The error the reader reported (`{"error": kind, "detail": …}`), else its last lines.
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

#[cfg(test)]
mod tests {
    use super::*;

    fn package() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/specconv/_asset_reader")
    }

    /// A Python 3 (the tests' own, else python3): the child carrier needs no usd-core to
    /// answer a layer request of a document with no overrides.
    fn child() -> Reader {
        let python = std::env::var_os("SPECCONV_PYTHON").unwrap_or_else(|| "python3".into());
        Reader::new(python, Duration::from_secs(60))
    }

    #[test]
    fn the_protocol_is_the_readers() {
        let (_, source) = MODULES.iter().find(|(n, _)| *n == "protocol").unwrap();
        assert!(source.contains(&format!("\nPROTOCOL = {PROTOCOL}\n")));
    }

    #[test]
    fn every_module_of_the_package_is_built_in() {
        let mut files: Vec<String> = std::fs::read_dir(package())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".py") && n != "bootstrap.py" && n != "__main__.py")
            .collect();
        files.sort();
        let mut built: Vec<String> = MODULES.iter().map(|(n, _)| format!("{n}.py")).collect();
        built.sort();
        assert_eq!(files, built);
        for (name, source) in MODULES {
            let file = std::fs::read_to_string(package().join(format!("{name}.py"))).unwrap();
            assert_eq!(file, source, "{name}.py");
        }
    }

    #[test]
    fn the_child_carrier_answers_in_the_protocol() {
        let plan = json!({"stage": "/nowhere/d.mtlx", "layer": "/nowhere/x", "documents": []});
        let answer = child()
            .ask(json!({"command": "layer", "plan": plan}))
            .unwrap();
        assert_eq!(answer, json!({"files": [], "protocol": PROTOCOL}));
        let err = child().ask(json!({"command": "nothing"})).unwrap_err();
        assert!(err.to_string().contains("no command 'nothing'"), "{err}");
    }

    fn in_process(status: i32, answer: String) -> Reader {
        Reader::in_process("py".into(), Arc::new(move |_| Ok((status, answer.clone()))))
    }

    #[test]
    fn an_answer_in_no_or_another_protocol_is_refused_saying_what_to_do() {
        let stage = r#"{"stage": "/s.usda", "materials": 0, "bound_prims": 0,
            "composition_errors": [], "textures": []"#;
        let read = |protocol: &str| {
            in_process(0, format!("{stage}{protocol}}}")).read(Path::new("/s.usda"), None)
        };
        let e = read("").unwrap_err().to_string();
        assert!(e.contains("answered with no protocol version"), "{e}");
        assert!(
            e.contains("reads protocol 1") && e.contains("reinstall specconv"),
            "{e}"
        );
        let e = read(r#", "protocol": 2"#).unwrap_err().to_string();
        assert!(e.contains("answered in protocol 2"), "{e}");
        let ours = read(r#", "protocol": 1"#).unwrap();
        assert_eq!(ours.stage, Path::new("/s.usda"));
    }

    #[test]
    fn failures_are_read_from_the_answer() {
        let no_usd = r#"{"error": "no-pxr", "detail": "No module named 'pxr'", "protocol": 1}"#;
        let e = in_process(3, no_usd.into()).read(Path::new("/s.usda"), None);
        assert!(matches!(e, Err(Error::NoUsd { .. })), "{e:?}");
        let open = r#"{"error": "open", "detail": "no such layer", "protocol": 1}"#;
        let e = in_process(2, open.into()).read(Path::new("/s.usda"), None);
        let e = e.unwrap_err().to_string();
        assert_eq!(e, "usd-core cannot open the stage: no such layer");
    }
}
