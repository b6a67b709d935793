//! The batch surface a wrapper script reads: global options, one error format, one table of
//! exit statuses, settings checked once before the first input.

use crate::info::{arg, testdata};
use crate::runner::*;
use std::path::{Path, PathBuf};

/// The lines specconv itself wrote to standard error (libraries may add their own).
fn our_lines(stderr: &str) -> Vec<&str> {
    stderr
        .lines()
        .filter(|l| l.starts_with("specconv"))
        .collect()
}

/// A colour space, config or model that cannot work for any input fails once, before the
/// first input is read: one line, exit 2, nothing written, even for inputs that would fail.
#[test]
fn settings_that_cannot_work_fail_once_before_the_first_input() {
    let dir = Scratch::new("surface-precheck");
    let out = dir.path("out");
    std::fs::create_dir(&out).unwrap();
    let inputs = [
        testdata("images/srgb8.png"),
        testdata("images/rgb16.tif"),
        dir.path("missing.png"),
    ];
    let batch = |extra: &[&str]| {
        let mut a: Vec<String> = inputs.iter().map(|p| arg(p).to_string()).collect();
        a.extend(["-o".into(), arg(&out).into()]);
        a.extend(extra.iter().map(|s| s.to_string()));
        Cmd::new(a).run()
    };
    batch(&["--colorspace", "ACEScgg"]).one_error_line(2, &["unknown colour space 'ACEScgg'"]);
    // A data space names data textures (skipped or copied by --data): only `--data fail`
    // makes it fail every input.
    batch(&["--colorspace", "Raw", "--data", "fail"])
        .one_error_line(2, &["holds data, not colour"]);
    batch(&["--ocio", "/no/such.ocio"]).one_error_line(2, &["/no/such.ocio: no such file"]);
    let c = testdata("ocio/no_interchange.ocio");
    batch(&["--ocio", arg(&c), "--colorspace", "linear"]).one_error_line(
        2,
        &["neither a cie_xyz_d65_interchange nor an aces_interchange role"],
    );
    batch(&["--model", "/no/model.json"]).one_error_line(2, &["/no/model.json"]);
    batch(&["--json", "-j", "0"]).one_error_line(2, &["-j/--threads"]);
    batch(&["--tile", "0", "64"]).one_error_line(2, &["--tile 0 64"]);
    assert!(
        std::fs::read_dir(&out).unwrap().next().is_none(),
        "nothing written"
    );
    // The same inputs with usable settings: two converted, the missing one fails (exit 1).
    let ok = batch(&["-q"]);
    ok.fails(1, &["missing.png"]);
    assert_eq!(our_lines(&ok.stderr).len(), 1, "{}", ok.stderr);
}

/// A missing output directory is a usage error (2) in every form and every command that
/// writes a file, found before anything is read.
#[test]
fn a_missing_output_directory_is_exit_2_everywhere() {
    let dir = Scratch::new("surface-outdir");
    let png = testdata("images/srgb8.png");
    let gone = dir.path("gone");
    let in_gone = gone.join("x.exr");
    let template = format!("{}/{{stem}}.exr", gone.display());
    let model = gone.join("m.json");
    let cc = colorchecker();
    for args in [
        vec![arg(&png), arg(&in_gone)],
        vec!["convert", arg(&png), arg(&in_gone)],
        // (`-o DIR` makes DIR, as `asset -o` does: tests/it/plans.rs, issue 56 item 6.)
        vec![arg(&png), "--output-template", &template],
        vec!["to-rgb", arg(&png), arg(&in_gone)],
        vec!["train", "--spectra", arg(&cc), "-o", arg(&model)],
    ] {
        Cmd::new(&args).run().one_error_line(
            2,
            &[&format!(
                "the output directory {} does not exist",
                gone.display()
            )],
        );
    }
    assert!(!gone.exists());
}

/// `--ocio` is global: before the subcommand, after it, or before the default conversion's
/// paths, it names the same config.
#[test]
fn global_options_work_before_the_subcommand() {
    let cfg = testdata("ocio/aces_interchange_only.ocio");
    let after = Cmd::new(["colorspaces", "--json", "--ocio", arg(&cfg)]).run();
    let before = Cmd::new(["--ocio", arg(&cfg), "colorspaces", "--json"]).run();
    assert_eq!(before.ok(), after.ok());
    let v: serde_json::Value = serde_json::from_str(before.ok()).unwrap();
    assert!(
        v["config"]
            .as_str()
            .unwrap()
            .contains("aces_interchange_only.ocio"),
        "{}",
        v["config"]
    );
    // Wrong either way round, in every command that reads a config.
    for args in [
        vec!["--ocio", "/no/such.ocio", "colorspaces"],
        vec!["--ocio", "/no/such.ocio", "info", "x.png"],
        vec!["info", "x.png", "--ocio", "/no/such.ocio"],
        vec!["--ocio", "/no/such.ocio", "to-rgb", "x.exr", "y.exr"],
        vec!["--ocio", "/no/such.ocio", "convert", "x.png", "y.exr"],
        vec!["--ocio", "/no/such.ocio", "x.png", "y.exr"],
    ] {
        Cmd::new(&args)
            .run()
            .one_error_line(2, &["/no/such.ocio: no such file"]);
    }
}

/// Every command reports an error on one line with each cause once (to-rgb used to print
/// its cause twice).
#[test]
fn every_command_reports_errors_on_one_line_with_each_cause_once() {
    let dir = Scratch::new("surface-errors");
    let png = testdata("images/srgb8.png");
    let out = dir.path("x.exr");
    let rgb = testdata("images/half_tiled_alpha.exr");
    let r = Cmd::new(["to-rgb", arg(&rgb), arg(&out)]).run();
    r.one_error_line(1, &["not a spectral EXR"]);
    assert_eq!(
        r.stderr.matches("half_tiled_alpha.exr").count(),
        1,
        "{}",
        r.stderr
    );
    let r = Cmd::new(["to-rgb", arg(&png), arg(&out)]).run();
    r.one_error_line(1, &["file identifier missing"]);
    let missing = dir.path("missing.exr");
    for args in [
        vec!["to-rgb", arg(&missing), arg(&out)],
        vec!["info", arg(&missing)],
        vec!["preview", arg(&missing), "-o", arg(&dir.path("p.png"))],
    ] {
        let r = Cmd::new(&args).run();
        r.one_error_line(1, &[]);
        // The file is named once per line, whatever wraps the reader's message.
        assert_eq!(r.stderr.matches("missing.exr").count(), 1, "{}", r.stderr);
    }
    // Command-line errors too: clap's message and tip on the one line, no usage block.
    Cmd::new(["completions", "tcsh"])
        .run()
        .one_error_line(2, &["invalid value 'tcsh'", "possible values"]);
    Cmd::new(["info", "--ocoi", "x"])
        .run()
        .one_error_line(2, &["--ocoi", "--ocio"]);
    // The conversion's options before another subcommand are refused, not ignored.
    Cmd::new(["--force", "info", arg(&png)])
        .run()
        .one_error_line(2, &["'force'", "'info'"]);
    let ragged = dir.write("ragged.csv", "wavelength,a\n400,0.1\n410\n");
    Cmd::train(arg(&ragged))
        .args(["-o", arg(&dir.path("m.json"))])
        .run()
        .one_error_line(1, &["ragged.csv"]);
}

/// `report` says when a model has fewer clusters than asked for, and why: the ColorChecker's
/// 24 spectra cannot make two clusters of the default minimum of 20.
#[test]
fn report_says_when_fewer_clusters_were_grown_and_why() {
    let cc = colorchecker();
    let out = Cmd::new([
        "report",
        "--spectra",
        arg(&cc),
        "--clusters",
        "1,4",
        "--steps",
        "10",
        "--colours",
        "1024",
        "--jakob-resolution",
        "8",
        "-j",
        "1",
        "--json",
    ])
    .run();
    let rows: serde_json::Value = serde_json::from_str(out.ok()).unwrap();
    let four = rows
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["method"] == "otsu2018")
        .unwrap();
    assert_eq!(four["setting"], "1 of 4 clusters", "{four}");
    let note = four["note"].as_str().unwrap();
    assert!(
        note.contains("4 clusters asked for, 1 grown")
            && note.contains("fewer than 2 × --min-cluster-size 20"),
        "{note}"
    );
    assert!(out.stderr.contains(note), "{}", out.stderr);
    for r in rows.as_array().unwrap() {
        if r["method"] != "otsu2018" {
            assert!(r["note"].is_null(), "{r}");
        }
    }
}

/// The keys a section of docs/json.md lists in its table, sorted.
fn documented_keys(section: &str) -> Vec<String> {
    let doc = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/json.md"))
        .unwrap();
    let start = doc
        .find(section)
        .unwrap_or_else(|| panic!("{section} in docs/json.md"));
    let mut keys: Vec<String> = doc[start..]
        .lines()
        .skip(1)
        .take_while(|l| !l.starts_with("## "))
        .filter_map(|l| l.strip_prefix("| `"))
        .map(|l| l[..l.find('`').unwrap()].to_string())
        .collect();
    keys.sort();
    keys
}

/// A record's keys, sorted.
fn keys(v: &serde_json::Value) -> Vec<String> {
    let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
    k.sort();
    k
}

fn records(stdout: &str) -> Vec<serde_json::Value> {
    stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("not JSON ({e}): {l}")))
        .collect()
}

/// Converted, failed and skipped inputs give records with the same keys, the ones
/// docs/json.md documents; null where a key does not apply; the colour space and the rule
/// that chose it apart; the error without the path.
#[test]
fn convert_records_have_one_schema() {
    let dir = Scratch::new("surface-json");
    let out = dir.path("out");
    std::fs::create_dir(&out).unwrap();
    // A 16-bit TIFF declares nothing: sRGB texture by default.
    let tif = testdata("images/rgb16.tif");
    let exr = testdata("images/float_tiled_alpha.exr");
    let missing = dir.path("missing.tif");
    let truncated = testdata("broken/truncated.exr");
    let run = |extra: &[&str]| {
        let mut a = vec![arg(&tif), arg(&exr), arg(&missing), arg(&truncated)];
        a.extend(["-o", arg(&out), "--json", "--mip", "0"]);
        a.extend(extra);
        Cmd::new(a).run()
    };
    let first = run(&[]);
    first.fails(1, &[]);
    let again = run(&["-u"]);
    again.fails(1, &[]);
    let flagged = Cmd::new([
        arg(&tif),
        arg(&dir.path("flag.exr")),
        "--json",
        "--colorspace",
        "lin_rec709",
        "--unbounded",
    ])
    .run();
    let mut all = records(&first.stdout);
    all.extend(records(&again.stdout));
    all.extend(records(flagged.ok()));
    assert_eq!(all.len(), 9);
    let documented = documented_keys("## convert --json");
    assert!(documented.len() >= 17, "{documented:?}");
    for r in &all {
        assert_eq!(keys(r), documented, "{r}");
    }
    let by = |input: &Path, status: &str| {
        all.iter()
            .find(|r| r["input"] == arg(input) && r["status"] == status)
            .unwrap_or_else(|| panic!("{} {status}", input.display()))
    };
    let ok = by(&tif, "ok");
    assert_eq!(ok["colorspace"], "sRGB - Texture");
    assert_eq!(ok["colorspace_rule"], "default");
    assert_eq!(
        (ok["width"].as_u64(), ok["height"].as_u64()),
        (Some(61), Some(47))
    );
    assert_eq!(ok["pixels"].as_u64(), Some(61 * 47));
    assert_eq!(
        (ok["levels"].as_u64(), ok["bands"].as_u64()),
        (Some(1), Some(36))
    );
    assert!(
        ok["bounded"]["projected"].is_u64() && ok["error"].is_null(),
        "{ok}"
    );
    assert!(
        ok["skip_reason"].is_null() && ok["above_one"].is_u64(),
        "{ok}"
    );
    // OpenImageIO says "Linear" for every EXR: not a declaration. Without chromaticities
    // OpenEXR means linear Rec.709, D65 (docs/colour.md).
    // Its values are mostly above 1 (an HDR plate's): a reflectance conversion clips them.
    let default = by(&exr, "clipped");
    assert_eq!(default["colorspace"], "Linear Rec.709 (sRGB)");
    assert_eq!(default["colorspace_rule"], "default");
    let flag = &records(&flagged.stdout)[0];
    assert_eq!(flag["colorspace"], "Linear Rec.709 (sRGB)");
    assert_eq!(flag["colorspace_rule"], "colorspace-option");
    assert!(
        flag["bounded"].is_null(),
        "--unbounded has no counts: {flag}"
    );
    let skipped = by(&tif, "skipped");
    assert_eq!(skipped["skip_reason"], "up to date");
    assert!(
        skipped["colorspace"].is_null()
            && skipped["pixels"].is_null()
            && skipped["error"].is_null()
    );
    for bad in [&missing, &truncated] {
        let failed = by(bad, "failed");
        let error = failed["error"].as_str().unwrap();
        let name = bad.file_name().unwrap().to_str().unwrap();
        assert!(!error.is_empty() && !error.contains(name), "{error}");
        assert!(failed["colorspace"].is_null() && failed["skip_reason"].is_null());
        assert_eq!(
            failed["output"],
            arg(&out.join(format!("{}_spectral.exr", name.split('.').next().unwrap())))
        );
    }
}

/// `info --json` prints one object per file, one per line, all with the keys docs/json.md
/// lists; a file that cannot be read is said on standard error and the others still shown.
#[test]
fn info_json_is_one_object_per_line() {
    let dir = Scratch::new("surface-info");
    let mut files: Vec<PathBuf> = std::fs::read_dir(testdata("images"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    let spectral = dir.path("s.exr");
    Cmd::new([arg(&files[0]), arg(&spectral), "--mip", "0"]).ok();
    files.push(spectral.clone());
    let mut args = vec!["info".to_string(), "--json".to_string()];
    args.extend(files.iter().map(|p| arg(p).to_string()));
    let out = Cmd::new(&args).run();
    let lines = records(out.ok());
    assert_eq!(lines.len(), files.len());
    let documented = documented_keys("## info --json");
    for (v, f) in lines.iter().zip(&files) {
        assert_eq!(keys(v), documented, "{}", f.display());
        assert_eq!(v["file"], arg(f));
    }
    let s = lines.last().unwrap();
    assert_eq!(s["spectral"]["reflective_nm"].as_array().unwrap().len(), 36);
    assert!(s["spectral"]["emissive_units"].is_null());

    let missing = dir.path("missing.exr");
    let out = Cmd::new([
        "info",
        "--json",
        arg(&files[0]),
        arg(&missing),
        arg(&files[1]),
    ])
    .run();
    out.fails(1, &["missing.exr"]);
    assert_eq!(records(&out.stdout).len(), 2);
    assert_eq!(our_lines(&out.stderr).len(), 1, "{}", out.stderr);
}

/// Runs specconv with standard error into a file, returning (exit code, what it wrote).
fn with_stderr_in_a_file(dir: &Scratch, args: &[&str], env: &[(&str, &str)]) -> (i32, String) {
    let log = dir.path("stderr.log");
    let cmd = env.iter().fold(Cmd::new(args), |c, &(k, v)| c.env(k, v));
    let status = cmd
        .command()
        .stdout(std::process::Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap())
        .status()
        .unwrap();
    (
        status.code().unwrap(),
        std::fs::read_to_string(&log).unwrap(),
    )
}

/// A batch ends with a summary that lists the failures again; progress goes into a file as
/// plain lines (every $SPECCONV_PROGRESS_SECONDS, here 0: at every step), not into a pipe
/// unless asked, and never with --progress never.
#[test]
fn batches_end_with_a_summary_and_log_plain_progress_into_files() {
    let dir = Scratch::new("surface-progress");
    let out = dir.path("out");
    std::fs::create_dir(&out).unwrap();
    let png = testdata("images/srgb8.png");
    let tif = testdata("images/rgb16.tif");
    let missing = dir.path("missing.png");
    let o = arg(&out);
    let every = [("SPECCONV_PROGRESS_SECONDS", "0")];
    let (code, log) = with_stderr_in_a_file(
        &dir,
        &[arg(&png), arg(&missing), arg(&tif), "-o", o],
        &every,
    );
    assert_eq!(code, 1, "{log}");
    for needle in [
        "specconv: progress: file 1 of 3 (",
        "specconv: progress: file 3 of 3 (",
        "% of it, batch ETA ",
        "specconv: 2 converted, 0 skipped, 1 failed in ",
    ] {
        assert!(log.contains(needle), "{needle:?} in\n{log}");
    }
    // The summary is last and lists the failure again, as its error line said it.
    let error = log
        .lines()
        .find(|l| l.starts_with("specconv: error: "))
        .unwrap()
        .strip_prefix("specconv: error: ")
        .unwrap();
    let tail: Vec<&str> = log.lines().rev().take(2).collect();
    assert_eq!(tail[0], format!("  failed: {error}"), "{log}");
    assert!(tail[1].starts_with("specconv: 2 converted"), "{log}");

    // -u: up to date inputs count as skipped.
    let (code, log) = with_stderr_in_a_file(&dir, &[arg(&png), arg(&tif), "-o", o, "-u"], &[]);
    assert_eq!(code, 0, "{log}");
    assert!(
        log.contains("specconv: 0 converted, 2 skipped, 0 failed in "),
        "{log}"
    );

    let (_, log) = with_stderr_in_a_file(
        &dir,
        &[
            arg(&png),
            arg(&tif),
            "-o",
            o,
            "--force",
            "--progress",
            "never",
        ],
        &every,
    );
    assert!(!log.contains("progress:"), "{log}");
    // Into a pipe: no progress unless --progress always.
    let piped = Cmd::new([arg(&png), arg(&tif), "-o", o, "--force"]).run();
    assert!(!piped.ok().contains("progress:") && !piped.stderr.contains("progress:"));
    let always = Cmd::new([arg(&png), arg(&tif), "-o", o, "--force"])
        .args(["--progress", "always"])
        .env("SPECCONV_PROGRESS_SECONDS", "0")
        .run();
    assert!(always.stderr.contains("specconv: progress: file 2 of 2"));
    // -q: errors only.
    let (_, log) = with_stderr_in_a_file(
        &dir,
        &[arg(&png), arg(&tif), "-o", o, "--force", "-q"],
        &every,
    );
    assert_eq!(log, "");
}

/// On a terminal (a pseudo-terminal from util-linux `script`), a live line says which file
/// of how many and the batch's ETA.
#[test]
fn a_terminal_sees_file_i_of_n_and_the_eta() {
    let dir = Scratch::new("surface-tty");
    let out = dir.path("out");
    std::fs::create_dir(&out).unwrap();
    let command = format!(
        "'{}' '{}' '{}' -o '{}'",
        binary().display(),
        arg(&testdata("images/srgb8.png")),
        arg(&testdata("images/rgb16.tif")),
        arg(&out)
    );
    let tty = std::process::Command::new("script")
        .args(["-qec", &command, "/dev/null"])
        .output()
        .expect("util-linux script runs");
    let text = String::from_utf8_lossy(&tty.stdout);
    assert_eq!(tty.status.code(), Some(0), "{text}");
    for needle in [
        "file 1 of 2: ",
        "file 2 of 2: ",
        "Mpixel/s",
        "ETA ",
        "specconv: 2 converted",
    ] {
        assert!(text.contains(needle), "{needle:?} in {text:?}");
    }
}

/// `simulate --help` shows a scene that can be copied as it is: saved to a file, it runs.
#[test]
fn simulate_help_shows_a_scene_that_runs_as_it_is() {
    let dir = Scratch::new("surface-scene");
    let help = Cmd::new(["simulate", "--help"]).run();
    let text = help.ok();
    let scene: String = text
        .lines()
        .skip_while(|l| !l.starts_with("Scene"))
        .skip(1)
        .take_while(|l| !l.starts_with("Examples:"))
        .map(|l| format!("{}\n", l.strip_prefix("  ").unwrap_or(l)))
        .collect();
    assert!(
        scene.contains("[[patches]]") && scene.contains("form_factors"),
        "{text}"
    );
    let path = dir.write("scene.toml", &scene);
    let report = Cmd::new(["simulate", "--scene", arg(&path), "--json"]).run();
    let v: serde_json::Value = serde_json::from_str(report.ok()).unwrap();
    assert!(v.is_object(), "{v}");
    // `-h` stays short.
    assert!(!Cmd::new(["simulate", "-h"])
        .ok()
        .stdout
        .contains("[[patches]]"));
}

/// The README's exit-status table is the one the man pages print (the program's own table).
#[test]
fn the_readme_documents_the_exit_statuses() {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    for (code, meaning) in specconv_cli::exit::TABLE {
        let row = format!("| {code} | {meaning} |");
        assert!(readme.contains(&row), "README lacks the row\n{row}");
    }
}

/// groff (the reference roff) renders every man page without a warning, and the examples
/// come out line for line, as they can be copied.
#[test]
fn groff_renders_every_man_page_with_its_examples_line_for_line() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("man");
    let mut pages: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    pages.sort();
    assert!(pages.len() >= 11, "{pages:?}");
    let groff = |page: &Path, extra: &[&str]| {
        let out = std::process::Command::new("groff")
            .args(["-k", "-man", "-Tutf8", "-ww"])
            .args(extra)
            .arg(page)
            .env("MANWIDTH", "100")
            .output()
            .expect("groff runs (Debian: groff-base)");
        assert!(out.status.success(), "{}", page.display());
        (
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    for page in &pages {
        let (_, warnings) = groff(page, &["-z"]);
        assert_eq!(warnings, "", "{}", page.display());
        // Plain text: no overstrike for bold.
        let (text, _) = groff(page, &["-P-cbou"]);
        for section in ["EXAMPLES", "EXIT STATUS", "ENVIRONMENT", "SEE ALSO"] {
            assert!(text.contains(section), "{} lacks {section}", page.display());
        }
    }
    let (text, _) = groff(&dir.join("specconv-simulate.1"), &["-P-cbou"]);
    for line in [
        "  [[patches]]",
        "  colour = [0.8, 0.1, 0.1]",
        "  specconv simulate --scene scene.toml",
    ] {
        assert!(
            text.lines().any(|l| l.trim_start() == line.trim_start()),
            "{line:?} is not a line of\n{text}"
        );
    }
}
