//! OpenImageIO's ≈260 libraries are loaded only by a command that reads an image (issue 19):
//! the binary has no link-time dependency on them, `--version`, `train` and `eval` never load
//! them, and a conversion, which does, still works. It loads them through the shim installed
//! beside the binary (or in `../lib/specconv/`), never from memory or the temporary folder
//! (issue 30): a copy of the binary with its shim works from a read-only folder, one without
//! it says what to copy where.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::convert::testdata;
use crate::runner::*;

/// The shim's file name (oiio-sys's `SHIM_FILE`).
const SHIM: &str = "libspecconv_oiio.so";

/// The libraries the dynamic loader loaded while `cmd` ran (`LD_DEBUG=files`), after checking
/// that it succeeded.
fn loaded(cmd: Cmd) -> Vec<String> {
    let out = cmd.env("LD_DEBUG", "files").run();
    assert_eq!(out.code, 0, "{}", out.stderr);
    let mut libs: Vec<String> = out
        .stderr
        .lines()
        .filter_map(|l| l.split_once("file=")?.1.split_whitespace().next())
        .map(str::to_owned)
        .collect();
    libs.sort();
    libs.dedup();
    assert!(
        libs.iter().any(|l| l.starts_with("libc.so")),
        "LD_DEBUG=files said nothing of libc: is this glibc's loader?\n{}",
        out.stderr
    );
    libs
}

fn openimageio(libs: &[String]) -> Vec<&String> {
    libs.iter()
        .filter(|l| l.contains("libOpenImageIO"))
        .collect()
}

#[test]
fn the_binary_does_not_link_openimageio() {
    let ldd = tool("ldd", &[binary().to_str().unwrap()]);
    assert!(ldd.contains("libc.so"), "{ldd}");
    assert!(
        !ldd.contains("libOpenImageIO"),
        "specconv depends on OpenImageIO when it starts again; only ffi/oiio-sys's embedded \
         shim may:\n{ldd}"
    );
}

#[test]
fn commands_that_read_no_image_do_not_load_openimageio() {
    let dir = Scratch::new("libraries-no-image");
    let model = dir.path("cc.json");
    for cmd in [
        Cmd::new(["--version"]),
        Cmd::train(colorchecker())
            .args(["--min-cluster-size", "4", "-o"])
            .arg(&model),
        Cmd::eval(colorchecker()),
    ] {
        let libs = loaded(cmd.clone());
        let oiio = openimageio(&libs);
        assert!(oiio.is_empty(), "{cmd:?} loaded {oiio:?}");
    }
    assert!(model.is_file());
}

#[test]
fn a_conversion_loads_openimageio_and_still_works() {
    let dir = Scratch::new("libraries-convert");
    let output = dir.path("out.exr");
    let libs = loaded(Cmd::convert(testdata("srgb8.png"), &output));
    // The check above sees OpenImageIO where it is loaded.
    assert!(!openimageio(&libs).is_empty(), "{libs:?}");
    // Through the shim beside the binary (not a copy in memory, /proc/self/fd/N).
    let beside = std::fs::canonicalize(binary())
        .unwrap()
        .with_file_name(SHIM);
    let shims: Vec<_> = libs
        .iter()
        .filter(|l| l.contains("specconv_oiio"))
        .collect();
    assert_eq!(shims, [&beside.to_string_lossy().into_owned()], "{libs:?}");
    let img = specconv_exr::read(&output).unwrap();
    assert_eq!(img.bands.len(), 36);
    assert!(img.bands.iter().flatten().all(|v| v.is_finite()));
}

/// A conversion where running code from memory or the temporary folder is impossible, as
/// endpoint security, SELinux and `noexec` mounts make it on render nodes: under strace,
/// `memfd_create` fails with EPERM, and TMPDIR is under a plain file, where nothing can be
/// created, not even by root. The conversion works, asks for no in-memory file at all, and
/// opens the shim beside the binary.
#[test]
fn a_conversion_runs_nothing_from_memory_or_the_temporary_folder() {
    let dir = Scratch::new("libraries-no-memfd");
    let not_a_folder = dir.write("not-a-folder", "");
    let (output, log) = (dir.path("out.exr"), dir.path("strace.log"));
    let out = Command::new("strace")
        .args(["-f", "-qq", "-o"])
        .arg(&log)
        .args(["-e", "trace=memfd_create,openat,open,creat"])
        .args(["-e", "inject=memfd_create:error=EPERM"])
        .arg(binary())
        .arg(testdata("srgba8.tx"))
        .arg(&output)
        .env("TMPDIR", not_a_folder.join("tmp"))
        .output()
        .unwrap_or_else(|e| panic!("strace must be installed (.ci/run installs it): {e}"));
    let log = std::fs::read_to_string(&log).unwrap_or_else(|e| {
        panic!(
            "strace wrote no log ({e}); can it trace here (ptrace)?\n{}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    assert!(
        out.status.success(),
        "{}\n{log}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        !log.contains("memfd_create("),
        "asked for an in-memory file:\n{log}"
    );
    // The one shim, opened from beside the binary.
    let beside = std::fs::canonicalize(binary())
        .unwrap()
        .with_file_name(SHIM);
    let opened: Vec<&str> = log.lines().filter(|l| l.contains(SHIM)).collect();
    assert!(
        !opened.is_empty()
            && opened.iter().all(|l| {
                l.contains(&format!("\"{}\"", beside.display())) && l.contains("O_RDONLY")
            }),
        "{opened:#?}"
    );
    // The output is a real image (nothing else checks it under strace).
    let img = specconv_exr::read(&output).unwrap();
    assert_eq!(img.bands.len(), 36);
}

/// An installation: `files` (names in target/<profile>/) copied under `root` at the relative
/// paths given, then the folders made read-only. Returns `root`, under cargo's temporary folder
/// (the system's may be `noexec`, as on the render nodes this is about).
fn install(name: &str, files: &[(&str, &str)]) -> Installation {
    let root = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("libraries-{name}-{}", std::process::id()));
    let _ = make_writable(&root);
    let _ = std::fs::remove_dir_all(&root);
    let built = std::fs::canonicalize(binary()).unwrap();
    for (file, to) in files {
        let to = root.join(to);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(built.with_file_name(file), &to).unwrap();
    }
    let installation = Installation(root);
    installation.read_only();
    installation
}

/// A folder tree made with [`install`], removed at the end.
struct Installation(PathBuf);

impl Installation {
    fn read_only(&self) {
        walk(&self.0, &mut |p| {
            if p.is_dir() {
                set_mode(p, 0o555);
            }
        });
    }

    /// Every path under the installation, sorted.
    fn listing(&self) -> Vec<PathBuf> {
        let mut all = Vec::new();
        walk(&self.0, &mut |p| all.push(p.to_owned()));
        all.sort();
        all
    }

    fn run(&self, program: &str, args: &[&Path]) -> Output {
        output(Command::new(self.0.join(program)).args(args))
    }

    /// Runs `program` as on a locked-down render node where the machine allows it (user and
    /// mount namespaces, `unshare -rm`): the installation mounted read-only (even to root) and
    /// /tmp a new, empty `noexec` tmpfs; else as [`Installation::run`] (the folders are
    /// read-only to all but root).
    fn run_sealed(&self, program: &str, args: &[&Path]) -> Output {
        const SEAL: &str = "mount -t tmpfs -o noexec,nosuid,nodev tmpfs /tmp && \
                            mount --bind \"$1\" \"$1\" && mount -o remount,bind,ro \"$1\" && \
                            shift && exec \"$@\"";
        // The checkout and target folder must not be under the /tmp that is replaced.
        let outside = [env!("CARGO_MANIFEST_DIR"), env!("CARGO_TARGET_TMPDIR")]
            .iter()
            .all(|p| !Path::new(p).starts_with("/tmp"));
        let namespaces = outside
            && Command::new("unshare")
                .args(["-rm", "true"])
                .status()
                .is_ok_and(|s| s.success());
        if !namespaces {
            eprintln!("no user and mount namespaces here (or the checkout is in /tmp): run as is");
            return self.run(program, args);
        }
        output(
            Command::new("unshare")
                .args(["-rm", "--propagation", "private", "sh", "-c", SEAL, "sh"])
                .arg(&self.0)
                .arg(self.0.join(program))
                .args(args),
        )
    }
}

fn output(command: &mut Command) -> Output {
    let out = command.output().expect("the installed binary runs");
    Output {
        code: out.status.code().expect("exited, not killed"),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

impl Drop for Installation {
    fn drop(&mut self) {
        let _ = make_writable(&self.0);
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn walk(path: &Path, visit: &mut dyn FnMut(&Path)) {
    visit(path);
    if path.is_dir() {
        for e in std::fs::read_dir(path).unwrap() {
            walk(&e.unwrap().path(), visit);
        }
    }
}

fn set_mode(path: &Path, mode: u32) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(mode)).unwrap();
}

fn make_writable(root: &Path) -> std::io::Result<()> {
    std::fs::metadata(root)?;
    walk(root, &mut |p| {
        if p.is_dir() {
            set_mode(p, 0o755);
        }
    });
    Ok(())
}

/// The binary and its shim copied into a read-only folder, and into a read-only `bin/` and
/// `lib/specconv/` prefix: each converts with /tmp `noexec` (where namespaces allow), and
/// writes nothing where it is installed.
#[test]
fn a_copy_with_its_shim_works_from_a_read_only_folder() {
    // Not under /tmp, which the sealed run replaces.
    let dir = Installation(
        Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join(format!("libraries-installed-out-{}", std::process::id())),
    );
    std::fs::create_dir_all(&dir.0).unwrap();
    for (name, files, program) in [
        (
            "beside",
            &[("specconv", "specconv"), (SHIM, SHIM)],
            "specconv",
        ),
        (
            "prefix",
            &[
                ("specconv", "bin/specconv"),
                (SHIM, &*format!("lib/specconv/{SHIM}")),
            ],
            "bin/specconv",
        ),
    ] {
        let installed = install(name, files);
        let before = installed.listing();
        let output = dir.0.join(format!("{name}.exr"));
        installed
            .run_sealed(program, &[&testdata("srgb8.png"), &output])
            .ok();
        assert_eq!(specconv_exr::read(&output).unwrap().bands.len(), 36);
        assert_eq!(
            installed.listing(),
            before,
            "{name}: wrote where it is installed"
        );
    }
}

/// The binary copied without its shim starts and does everything but read images; a
/// conversion fails as an input that cannot be read does (status 1, one line), naming where
/// the shim was looked for and what to copy there, and writes nothing.
#[test]
fn a_copy_without_its_shim_says_what_to_copy_where() {
    let dir = Scratch::new("libraries-no-shim");
    let installed = install("bare", &[("specconv", "bin/specconv")]);
    assert!(installed
        .run("bin/specconv", &[Path::new("--version")])
        .ok()
        .starts_with("specconv "));
    let input = testdata("srgb8.png");
    let out = installed.run("bin/specconv", &[&input, &dir.path("out.exr")]);
    let (bin, lib) = (installed.0.join("bin"), installed.0.join("lib/specconv"));
    out.one_error_line(
        1,
        &[
            &format!(
                "{}: cannot be read: OpenImageIO could not be loaded",
                input.display()
            ),
            &format!("{}/{SHIM}", bin.display()),
            &format!("{}/{SHIM}", lib.display()),
            &format!("copy it into {} ", bin.display()),
        ],
    );
    assert!(dir.files().is_empty(), "{:?}", dir.files());
}
