//! The `specconv` binary and the outside tools, run from tests: a command line built from
//! its parts (`Cmd::convert(input, output).args(["-d", "float"]).ok()`), what it said, the
//! checks every test repeats (success; exit status, one `specconv: error:` line, nothing
//! written), a scratch directory, and the reference scripts in tests/ (Python with
//! colour-science and OpenImageIO's bindings, through `$SPECCONV_PYTHON`).

use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The built `specconv` binary: `$SPECCONV_BIN`, or beside the running test (cargo puts test
/// binaries in `target/<profile>/deps` and the crate's binaries one folder up, and builds them
/// before the integration tests of their package).
pub fn binary() -> PathBuf {
    if let Some(bin) = std::env::var_os("SPECCONV_BIN") {
        return bin.into();
    }
    let exe = std::env::current_exe().expect("the test knows its own path");
    let mut dir = exe.parent().expect("a test binary lies in a folder");
    if dir.ends_with("deps") {
        dir = dir.parent().expect("deps lies in the profile's folder");
    }
    let bin = dir.join(format!("specconv{}", std::env::consts::EXE_SUFFIX));
    assert!(
        bin.is_file(),
        "{} not found: build it (cargo test builds it for the `it` tests) or set SPECCONV_BIN",
        bin.display()
    );
    bin
}

/// A command line of the binary, built up and then run.
#[derive(Debug, Clone, Default)]
pub struct Cmd {
    args: Vec<OsString>,
    stdin: Option<Vec<u8>>,
    dir: Option<PathBuf>,
    /// Variables to set, or with `None` to remove.
    env: Vec<(OsString, Option<OsString>)>,
}

impl Cmd {
    /// `specconv ARGS…`: a command's name first, or the arguments of the default convert.
    pub fn new<I, S>(args: I) -> Cmd
    where
        I: IntoIterator<Item = S>,
        S: AsRef<OsStr>,
    {
        // Hermetic: the site default model of the machine running the tests changes nothing
        // (a test that sets it does so after this).
        Cmd::default().env_remove("SPECCONV_MODEL").args(args)
    }

    /// `specconv INPUT OUTPUT`: the main job.
    pub fn convert(input: impl AsRef<OsStr>, output: impl AsRef<OsStr>) -> Cmd {
        Cmd::new([input.as_ref(), output.as_ref()])
    }

    /// `specconv train --spectra SPECTRA`.
    pub fn train(spectra: impl AsRef<OsStr>) -> Cmd {
        Cmd::new([
            OsStr::new("train"),
            OsStr::new("--spectra"),
            spectra.as_ref(),
        ])
    }

    /// `specconv eval --spectra SPECTRA`.
    pub fn eval(spectra: impl AsRef<OsStr>) -> Cmd {
        Cmd::new([
            OsStr::new("eval"),
            OsStr::new("--spectra"),
            spectra.as_ref(),
        ])
    }

    /// `specconv to-rgb INPUT OUTPUT`.
    pub fn to_rgb(input: impl AsRef<OsStr>, output: impl AsRef<OsStr>) -> Cmd {
        Cmd::new([OsStr::new("to-rgb"), input.as_ref(), output.as_ref()])
    }

    pub fn arg(mut self, arg: impl AsRef<OsStr>) -> Cmd {
        self.args.push(arg.as_ref().to_owned());
        self
    }

    pub fn args<I, S>(mut self, args: I) -> Cmd
    where
        I: IntoIterator<Item = S>,
        S: AsRef<OsStr>,
    {
        self.args
            .extend(args.into_iter().map(|a| a.as_ref().to_owned()));
        self
    }

    /// What the binary reads on standard input (else nothing: stdin is closed).
    pub fn stdin(mut self, bytes: impl Into<Vec<u8>>) -> Cmd {
        self.stdin = Some(bytes.into());
        self
    }

    /// Runs in `dir` (relative paths, and `-`, are there).
    pub fn current_dir(mut self, dir: impl AsRef<Path>) -> Cmd {
        self.dir = Some(dir.as_ref().to_owned());
        self
    }

    /// Sets an environment variable for the run.
    pub fn env(mut self, key: impl AsRef<OsStr>, value: impl AsRef<OsStr>) -> Cmd {
        let value = Some(value.as_ref().to_owned());
        self.env.push((key.as_ref().to_owned(), value));
        self
    }

    /// Removes an environment variable for the run.
    pub fn env_remove(mut self, key: impl AsRef<OsStr>) -> Cmd {
        self.env.push((key.as_ref().to_owned(), None));
        self
    }

    /// The process to start, for tests that signal or watch it while it runs.
    pub fn command(&self) -> Command {
        let mut c = Command::new(binary());
        c.args(&self.args);
        for (key, value) in &self.env {
            match value {
                Some(v) => c.env(key, v),
                None => c.env_remove(key),
            };
        }
        if let Some(dir) = &self.dir {
            c.current_dir(dir);
        }
        c
    }

    /// Runs to the end and captures what it said.
    pub fn run(&self) -> Output {
        let mut c = self.command();
        c.stdin(if self.stdin.is_some() {
            Stdio::piped()
        } else {
            Stdio::null()
        });
        let out = match &self.stdin {
            None => c.output(),
            Some(bytes) => {
                use std::io::Write;
                let mut child = c
                    .stdout(Stdio::piped())
                    .stderr(Stdio::piped())
                    .spawn()
                    .expect("the binary runs");
                child
                    .stdin
                    .take()
                    .expect("stdin is piped")
                    .write_all(bytes)
                    .expect("the binary reads its input");
                child.wait_with_output()
            }
        }
        .expect("the binary runs");
        Output {
            code: out.status.code().expect("exited, not killed"),
            stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
            stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        }
    }

    /// As [`Cmd::run`] (standard input empty), but a run still going after `limit` is killed
    /// and fails the test ("still running"): for cases that used to hang, so that a test of
    /// them can fail but never hang CI.
    #[track_caller]
    pub fn run_within(&self, limit: std::time::Duration) -> Output {
        use std::io::Read;
        let start = std::time::Instant::now();
        let mut child = self
            .command()
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the binary runs");
        let drain = |mut pipe: Box<dyn Read + Send>| {
            std::thread::spawn(move || {
                let mut bytes = Vec::new();
                let _ = pipe.read_to_end(&mut bytes);
                String::from_utf8_lossy(&bytes).into_owned()
            })
        };
        let stdout = drain(Box::new(child.stdout.take().expect("piped")));
        let stderr = drain(Box::new(child.stderr.take().expect("piped")));
        let status = loop {
            if let Some(status) = child.try_wait().expect("the binary runs") {
                break status;
            }
            if start.elapsed() > limit {
                let _ = child.kill();
                let _ = child.wait();
                panic!("{:?} still running after {limit:?}: it hangs", self.args);
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        };
        Output {
            code: status.code().expect("exited, not killed"),
            stdout: stdout.join().expect("read"),
            stderr: stderr.join().expect("read"),
        }
    }

    /// Runs, asserts success, and returns what it said.
    #[track_caller]
    pub fn ok(&self) -> Output {
        let out = self.run();
        out.ok();
        out
    }

    /// Runs and asserts [`Output::fails`].
    #[track_caller]
    pub fn fails(&self, code: i32, needles: &[&str]) -> Output {
        let out = self.run();
        out.fails(code, needles);
        out
    }

    /// Runs and asserts [`Output::one_error_line`] and that `dir`'s files are as before.
    #[track_caller]
    pub fn refused(&self, dir: &Scratch, code: i32, needles: &[&str]) -> Output {
        let before = dir.files();
        let out = self.run();
        out.one_error_line(code, needles);
        assert_eq!(dir.files(), before, "{:?} wrote something", self.args);
        out
    }
}

/// What a run said.
pub struct Output {
    pub code: i32,
    pub stdout: String,
    pub stderr: String,
}

impl Output {
    /// Asserts success and returns stdout.
    #[track_caller]
    pub fn ok(&self) -> &str {
        assert_eq!(
            self.code, 0,
            "expected success\nstdout:\n{}\nstderr:\n{}",
            self.stdout, self.stderr
        );
        &self.stdout
    }

    /// Asserts failure with `code` and one `specconv: error:` line mentioning every `needle`.
    #[track_caller]
    pub fn fails(&self, code: i32, needles: &[&str]) {
        assert_eq!(
            self.code, code,
            "exit code\nstdout:\n{}\nstderr:\n{}",
            self.stdout, self.stderr
        );
        for n in needles {
            assert!(
                self.stderr.contains(n),
                "stderr lacks {n:?}:\n{}",
                self.stderr
            );
        }
        assert!(!self.stderr.contains("panicked"), "{}", self.stderr);
    }

    /// Exit `code` with exactly one line on standard error, `specconv: error: …`, holding every
    /// needle once.
    #[track_caller]
    pub fn one_error_line(&self, code: i32, needles: &[&str]) {
        self.fails(code, needles);
        let lines: Vec<&str> = self.stderr.lines().collect();
        assert_eq!(lines.len(), 1, "one line expected:\n{}", self.stderr);
        assert!(lines[0].starts_with("specconv: error: "), "{}", self.stderr);
        for n in needles {
            assert_eq!(lines[0].matches(n).count(), 1, "{n:?} once in {}", lines[0]);
        }
    }

    /// Standard output as one JSON value (`--json` of a single run).
    #[track_caller]
    pub fn json(&self) -> serde_json::Value {
        json(&self.stdout)
    }

    /// Standard output as one JSON value a line (`--json` of a batch).
    #[track_caller]
    pub fn json_lines(&self) -> Vec<serde_json::Value> {
        self.stdout
            .lines()
            .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
            .collect()
    }
}

/// `text` as JSON, or a panic that shows it.
#[track_caller]
pub fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap_or_else(|e| panic!("not JSON ({e}):\n{text}"))
}

/// A scratch directory removed when dropped.
///
/// It sits one level inside a folder of its own (`specconv-it-NAME-PID/work`), so a path a
/// test's files name with `../` resolves inside that private folder, never to whatever an
/// earlier run left in the shared temporary directory: a test that reads outside its scratch
/// fails on every machine, not only on a fresh one.
pub struct Scratch(pub PathBuf);

impl Scratch {
    pub fn new(name: &str) -> Scratch {
        let own = std::env::temp_dir().join(format!("specconv-it-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&own);
        let dir = own.join("work");
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    pub fn write(&self, name: &str, text: &str) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    /// Names of the files in the directory, sorted.
    pub fn files(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.0)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        // The private parent too: what a test wrote beside its scratch goes with it.
        let _ = std::fs::remove_dir_all(self.0.parent().unwrap_or(&self.0));
    }
}

/// Runs an outside tool (exrheader, oiiotool, …), asserts success, returns its stdout.
#[track_caller]
pub fn tool(name: &str, args: &[&str]) -> String {
    let out = Command::new(name)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("{name} must be installed (.ci/run installs it): {e}"));
    assert!(
        out.status.success(),
        "{name} {args:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The Python with colour-science and OpenImageIO's bindings: `$SPECCONV_PYTHON` (.ci/run
/// makes a venv), else `python3`.
pub fn python() -> String {
    std::env::var("SPECCONV_PYTHON").unwrap_or_else(|_| "python3".into())
}

/// Runs [`python`] with `args` (a script and its arguments, or `-c CODE …`); asserts success,
/// returns its stdout.
#[track_caller]
pub fn python_output<I, S>(args: I) -> Vec<u8>
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    let python = python();
    let out = Command::new(&python)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("{python}: {e}"));
    assert!(
        out.status.success(),
        "{python} with colour-science and OpenImageIO's bindings (set SPECCONV_PYTHON; \
         .ci/run makes a venv): {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// Runs the reference script tests/`name` with `args`; returns its stdout.
#[track_caller]
pub fn script<I, S>(name: &str, args: I) -> Vec<u8>
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests")
        .join(name);
    let args: Vec<OsString> = args.into_iter().map(|a| a.as_ref().to_owned()).collect();
    python_output(std::iter::once(path.into_os_string()).chain(args))
}

/// [`script`]'s output as JSON.
#[track_caller]
pub fn script_json<I, S>(name: &str, args: I) -> serde_json::Value
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    json(&String::from_utf8_lossy(&script(name, args)))
}
