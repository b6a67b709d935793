//! `specconv farm` on a real Slurm cluster (scripts/slurm-cluster.sh; .ci/run starts one), and
//! `convert --shard`. Outputs of the array are compared with a local convert of the same inputs
//! through OpenEXR's exrheader and OpenImageIO's oiiotool.

use crate::runner::*;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Whether a cluster answers. Without Slurm's commands the cluster tests are skipped, loudly,
/// unless `$SPECCONV_REQUIRE_SLURM` is set (CI sets it); a cluster installed but not running is
/// started, and one that cannot start is a failure.
fn cluster() -> bool {
    let installed = Command::new("sinfo")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !installed {
        assert!(
            std::env::var_os("SPECCONV_REQUIRE_SLURM").is_none(),
            "SPECCONV_REQUIRE_SLURM is set but Slurm's sinfo is not installed"
        );
        eprintln!(
            "\n*** SKIPPED: Slurm is not installed (no sinfo); the farm tests need \
             slurm-wlm and munge and scripts/slurm-cluster.sh start ***\n"
        );
        return false;
    }
    let up = || {
        Command::new("scontrol")
            .arg("ping")
            .output()
            .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).contains("is UP"))
    };
    if !up() {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/slurm-cluster.sh");
        let out = Command::new(&script).arg("start").output().unwrap();
        assert!(
            out.status.success() && up(),
            "Slurm is installed but no cluster answers, and {} start failed:\n{}",
            script.display(),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    true
}

/// A small texture of the given size: a gradient between two colours, 8-bit sRGB PNG.
fn texture(path: &Path, w: usize, h: usize, seed: usize) {
    let a = [
        0.1 + 0.05 * (seed % 7) as f64,
        0.3,
        0.8 - 0.04 * seed as f64,
    ];
    let fill = format!(
        "fill:topleft={},{},{}:topright=0.9,0.2,0.1:bottomleft=0.2,0.7,0.3:bottomright=0.5,0.5,0.5",
        a[0], a[1], a[2]
    );
    tool(
        "oiiotool",
        &[
            "--pattern",
            &fill,
            &format!("{w}x{h}"),
            "3",
            "-d",
            "uint8",
            "-o",
            path.to_str().unwrap(),
        ],
    );
}

fn json_lines(s: &str) -> Vec<Value> {
    s.lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect()
}

/// exrheader's description of a file, without the line that names the file.
fn header(p: &Path) -> String {
    tool("exrheader", &[p.to_str().unwrap()])
        .lines()
        .filter(|l| !l.starts_with("file "))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The same pixels (every channel, oiiotool --diff with no tolerance) and the same header.
fn assert_same_image(a: &Path, b: &Path) {
    assert_eq!(header(a), header(b), "{} and {}", a.display(), b.display());
    let diff = Command::new("oiiotool")
        .args(["--fail", "0", "--warn", "0"])
        .arg(a)
        .arg(b)
        .arg("--diff")
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&diff.stdout);
    assert!(
        diff.status.success() && said.contains("PASS"),
        "oiiotool --diff {} {}:\n{said}",
        a.display(),
        b.display()
    );
}

fn farm(args: &[&str]) -> Output {
    Cmd::new(std::iter::once("farm").chain(args.iter().copied())).run()
}

#[test]
fn a_job_array_reports_each_failure_and_retry_converts_exactly_those() {
    if !cluster() {
        return;
    }
    let dir = Scratch::new("farm-array");
    let (out, local) = (dir.path("out"), dir.path("local"));
    std::fs::create_dir_all(&out).unwrap();
    std::fs::create_dir_all(&local).unwrap();
    let mut inputs: Vec<PathBuf> = Vec::new();
    for k in 0..12 {
        let p = dir.path(&format!("tex{k:02}.png"));
        // Uneven sizes, so the plan has something to balance.
        if k != 3 && k != 7 {
            texture(&p, 16 + 24 * (k % 5), 16 + 8 * (k % 3), k);
        }
        inputs.push(p);
    }
    let (missing, corrupt) = (inputs[3].clone(), inputs[7].clone());
    std::fs::write(&corrupt, b"\x89PNG\r\n\x1a\nnot really").unwrap();
    let names: Vec<&str> = inputs.iter().map(|p| p.to_str().unwrap()).collect();
    let options = ["--compression", "zips", "--tile", "32", "32"];

    let mut args = vec!["submit"];
    args.extend(&names);
    args.extend([
        "-o",
        out.to_str().unwrap(),
        "--tasks",
        "4",
        "--wait",
        "--json",
    ]);
    args.extend(options);
    let submitted = farm(&args);
    assert_eq!(
        submitted.code, 1,
        "two inputs fail:\n{}\n{}",
        submitted.stdout, submitted.stderr
    );
    let lines = json_lines(&submitted.stdout);
    assert_eq!(lines[0]["tasks"], 4, "{}", submitted.stdout);
    let job_dir = PathBuf::from(lines[0]["job_dir"].as_str().unwrap());

    // status: every task ended, 10 files done and the 2 failures with their errors.
    let status = farm(&["status", job_dir.to_str().unwrap(), "--json"]);
    assert_eq!(status.code, 1, "{}", status.stderr);
    let s: Value = serde_json::from_str(&status.stdout).unwrap();
    let tasks = s["tasks"].as_array().unwrap();
    assert_eq!(tasks.len(), 4);
    assert!(
        tasks
            .iter()
            .all(|t| ["COMPLETED", "FAILED"].contains(&t["state"].as_str().unwrap())),
        "{tasks:?}"
    );
    let state_of = |p: &Path| {
        s["files"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["input"] == p.to_str().unwrap())
            .unwrap_or_else(|| panic!("{} not in the status", p.display()))
            .clone()
    };
    for p in &inputs {
        let f = state_of(p);
        let want = if *p == missing || *p == corrupt {
            "failed"
        } else {
            "done"
        };
        assert_eq!(f["state"], want, "{f}");
    }
    assert!(state_of(&missing)["error"]
        .as_str()
        .unwrap()
        .contains("no such file"));

    // collect: the same counts; running it twice says the same.
    let collected = farm(&["collect", job_dir.to_str().unwrap(), "--json"]);
    assert_eq!(
        collected.stdout,
        farm(&["collect", job_dir.to_str().unwrap(), "--json"]).stdout
    );
    let c: Value = serde_json::from_str(&collected.stdout).unwrap();
    assert_eq!(
        (
            c["files"].as_u64(),
            c["done"].as_u64(),
            c["failed"].as_u64(),
            c["pending"].as_u64()
        ),
        (Some(12), Some(10), Some(2), Some(0))
    );
    let failed: BTreeMap<String, String> = c["failures"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f["input"].as_str().unwrap().to_string(),
                f["error"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    assert_eq!(
        failed.keys().collect::<Vec<_>>(),
        [missing.to_str().unwrap(), corrupt.to_str().unwrap()]
    );
    assert!(
        c["pixels"].as_u64().unwrap() > 0 && c["seconds"].as_f64().unwrap() > 0.0,
        "{c}"
    );
    let text = farm(&["collect", job_dir.to_str().unwrap()]);
    assert!(
        text.stdout
            .contains("12 files: 10 done, 2 failed, 0 pending"),
        "{}",
        text.stdout
    );
    assert!(
        text.stdout.contains("tex03.png") && text.stdout.contains("farm retry"),
        "{}",
        text.stdout
    );

    // The array's outputs are those of a local convert of the same inputs with the same options.
    let good: Vec<&str> = names
        .iter()
        .copied()
        .filter(|n| !n.ends_with("tex03.png") && !n.ends_with("tex07.png"))
        .collect();
    let mut local_args = vec!["convert"];
    local_args.extend(&good);
    local_args.extend(["-o", local.to_str().unwrap()]);
    local_args.extend(options);
    Cmd::new(&local_args).ok();
    let spectral = |dir: &Path, p: &Path| {
        dir.join(format!(
            "{}_spectral.exr",
            p.file_stem().unwrap().to_string_lossy()
        ))
    };
    for p in inputs.iter().filter(|p| **p != missing && **p != corrupt) {
        assert_same_image(&spectral(&out, p), &spectral(&local, p));
    }
    // Made with the default model, whose every set allows commercial use: the outputs say so.
    let h = header(&spectral(&out, &inputs[0]));
    assert!(
        h.lines()
            .any(|l| l.contains("specconvCommercialUse") && l.contains("\"yes\"")),
        "{h}"
    );

    // Fix the two inputs; retry converts exactly those, leaving the others untouched.
    texture(&missing, 40, 24, 3);
    texture(&corrupt, 24, 40, 7);
    let mtimes = |ps: &[PathBuf]| -> Vec<_> {
        ps.iter()
            .map(|p| {
                std::fs::metadata(spectral(&out, p))
                    .and_then(|m| m.modified())
                    .ok()
            })
            .collect()
    };
    let before = mtimes(&inputs);
    let retried = farm(&["retry", job_dir.to_str().unwrap(), "--wait"]);
    assert_eq!(retried.code, 0, "{}\n{}", retried.stdout, retried.stderr);
    assert!(
        retried.stdout.contains("2 files in 2 tasks"),
        "{}",
        retried.stdout
    );
    let mut round1: Vec<Value> = Vec::new();
    for t in 0..2 {
        let log = std::fs::read_to_string(job_dir.join(format!("round-1/task-{t}.jsonl"))).unwrap();
        round1.extend(
            json_lines(&log)
                .into_iter()
                .filter(|l| l.get("input").is_some()),
        );
    }
    let mut converted: Vec<&str> = round1
        .iter()
        .map(|l| l["input"].as_str().unwrap())
        .collect();
    converted.sort_unstable();
    assert_eq!(
        converted,
        [missing.to_str().unwrap(), corrupt.to_str().unwrap()]
    );
    assert!(round1.iter().all(|l| l["status"] == "ok"), "{round1:?}");
    let after = mtimes(&inputs);
    for (k, (b, a)) in before.iter().zip(&after).enumerate() {
        if k == 3 || k == 7 {
            assert!(a.is_some());
        } else {
            assert_eq!(b, a, "tex{k:02}'s output was written again");
        }
    }
    let c: Value =
        serde_json::from_str(&farm(&["collect", job_dir.to_str().unwrap(), "--json"]).stdout)
            .unwrap();
    assert_eq!(
        (
            c["done"].as_u64(),
            c["failed"].as_u64(),
            c["pending"].as_u64()
        ),
        (Some(12), Some(0), Some(0))
    );
    // A second retry finds nothing to do and submits nothing.
    let manifest = std::fs::read(job_dir.join("manifest.json")).unwrap();
    let again = farm(&["retry", job_dir.to_str().unwrap()]);
    assert_eq!(again.code, 0);
    assert!(
        again.stdout.contains("nothing to retry"),
        "{}",
        again.stdout
    );
    assert_eq!(
        std::fs::read(job_dir.join("manifest.json")).unwrap(),
        manifest
    );
    assert!(!job_dir.join("round-2").exists());
}

#[test]
fn a_task_cancelled_mid_file_leaves_no_partial_output_and_retry_completes_it() {
    if !cluster() {
        return;
    }
    let dir = Scratch::new("farm-cancel");
    let out = dir.path("out");
    std::fs::create_dir_all(&out).unwrap();
    // Big enough that one thread takes seconds: the task is cancelled while writing it.
    let big = dir.path("big.exr");
    noise(&big, 2048, "half");
    let small: Vec<PathBuf> = (0..3).map(|k| dir.path(&format!("small{k}.png"))).collect();
    for (k, p) in small.iter().enumerate() {
        texture(p, 32, 32, k);
    }
    let mut args = vec!["submit", big.to_str().unwrap()];
    args.extend(small.iter().map(|p| p.to_str().unwrap()));
    args.extend(["-o", out.to_str().unwrap(), "--tasks", "2", "--json"]);
    let submitted = farm(&args);
    let lines = json_lines(submitted.ok());
    let job_dir = PathBuf::from(lines[0]["job_dir"].as_str().unwrap());
    let job_id = lines[0]["job_id"].as_str().unwrap().to_string();
    // The plan puts the big input alone in one task (balanced by pixels).
    let manifest: Value =
        serde_json::from_str(&std::fs::read_to_string(job_dir.join("manifest.json")).unwrap())
            .unwrap();
    let plan = &manifest["rounds"][0]["tasks"];
    let big_task = (0..2)
        .find(|&t| plan[t].as_array().unwrap().contains(&Value::from(0)))
        .unwrap();
    assert_eq!(plan[big_task], serde_json::json!([0]), "{plan}");

    // Cancel the big input's task once its temporary output exists: mid-file.
    let writing = || {
        std::fs::read_dir(&out).unwrap().any(|e| {
            let n = e.unwrap().file_name().to_string_lossy().into_owned();
            n.starts_with(".big_spectral.exr.specconv-") && n.ends_with(".tmp")
        })
    };
    let start = std::time::Instant::now();
    while !writing() {
        assert!(
            start.elapsed().as_secs() < 600,
            "the big input's task never started writing (hang guard)"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    tool("scancel", &[&format!("{job_id}_{big_task}")]);
    loop {
        let c: Value =
            serde_json::from_str(&farm(&["collect", job_dir.to_str().unwrap(), "--json"]).stdout)
                .unwrap();
        if c["running"] == false {
            assert_eq!(
                (
                    c["done"].as_u64(),
                    c["pending"].as_u64(),
                    c["failed"].as_u64()
                ),
                (Some(3), Some(1), Some(0)),
                "{c}"
            );
            assert_eq!(c["pending_files"][0]["input"], big.to_str().unwrap());
            assert!(
                c["pending_files"][0]["why"]
                    .as_str()
                    .unwrap()
                    .contains("CANCELLED"),
                "{c}"
            );
            break;
        }
        assert!(
            start.elapsed().as_secs() < 600,
            "the array never ended (hang guard)"
        );
        std::thread::sleep(std::time::Duration::from_millis(200));
    }
    let big_out = out.join("big_spectral.exr");
    assert!(!big_out.exists(), "a cancelled task left an output");
    // SIGTERM reached the conversion, which removed its temporary file.
    assert!(!writing(), "a cancelled task left its temporary file");
    let status = farm(&["status", job_dir.to_str().unwrap()]);
    assert!(status.stdout.contains("CANCELLED"), "{}", status.stdout);

    let retried = farm(&["retry", job_dir.to_str().unwrap(), "--wait"]);
    assert_eq!(retried.code, 0, "{}\n{}", retried.stdout, retried.stderr);
    assert!(
        retried.stdout.contains("1 file in 1 task"),
        "{}",
        retried.stdout
    );
    assert!(
        retried
            .stdout
            .contains("4 files: 4 done, 0 failed, 0 pending"),
        "{}",
        retried.stdout
    );
    assert!(tool("exrheader", &[big_out.to_str().unwrap()]).contains("spectralLayoutVersion"));
    let leftovers: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

/// Inputs `convert --shard I/N` converts, from its JSON records.
fn shard_inputs(inputs: &[&str], out: &Path, shard: &str, task_id: Option<&str>) -> Vec<String> {
    let cmd = Cmd::new(inputs).args(["-o", out.to_str().unwrap(), "--json", "--force"]);
    let cmd = cmd.args(["--mip", "0", "--shard", shard]);
    let cmd = match task_id {
        Some(id) => cmd.env("SLURM_ARRAY_TASK_ID", id),
        None => cmd.env_remove("SLURM_ARRAY_TASK_ID"),
    };
    json_lines(&cmd.ok().stdout)
        .iter()
        .map(|l| {
            assert_eq!(l["status"], "ok", "{l}");
            l["input"].as_str().unwrap().to_string()
        })
        .collect()
}

#[test]
fn n_shards_convert_every_input_exactly_once_with_the_plan_farm_submit_prints() {
    let dir = Scratch::new("farm-shard");
    let out = dir.path("out");
    std::fs::create_dir_all(&out).unwrap();
    // Uneven sizes: one large, several small, two equal (ties).
    let sizes = [
        (200, 150),
        (16, 16),
        (64, 32),
        (16, 16),
        (120, 8),
        (40, 90),
        (33, 17),
    ];
    let inputs: Vec<PathBuf> = sizes
        .iter()
        .enumerate()
        .map(|(k, &(w, h))| {
            let p = dir.path(&format!("in{k}.png"));
            texture(&p, w, h, k);
            p
        })
        .collect();
    let names: Vec<&str> = inputs.iter().map(|p| p.to_str().unwrap()).collect();
    for n in [1, 3, 4] {
        let mut seen: Vec<String> = Vec::new();
        let mut shards = Vec::new();
        for i in 0..n {
            let got = shard_inputs(&names, &out, &format!("{i}/{n}"), None);
            seen.extend(got.iter().cloned());
            shards.push(got);
        }
        seen.sort();
        let mut all: Vec<String> = names.iter().map(|s| s.to_string()).collect();
        all.sort();
        assert_eq!(seen, all, "{n} shards");
        // auto/N takes I from Slurm's array task id.
        assert_eq!(
            shard_inputs(
                &names,
                &out,
                &format!("auto/{n}"),
                Some(&(n - 1).to_string())
            ),
            shards[n - 1]
        );
        // farm submit --dry-run prints the same plan, and writes and submits nothing.
        let mut args = vec!["submit"];
        args.extend(&names);
        let n_text = n.to_string();
        args.extend(["-o", out.to_str().unwrap(), "--tasks", &n_text, "--dry-run"]);
        let before = std::fs::read_dir(&out).unwrap().count();
        let dry = farm(&args);
        let printed = dry.ok();
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), before);
        assert!(
            printed.contains("#!/bin/bash") && printed.contains(&format!("--array=0-{}", n - 1)),
            "{printed}"
        );
        let mut planned: Vec<Vec<String>> = Vec::new();
        for line in printed.lines() {
            if line.starts_with("# task ") {
                planned.push(Vec::new());
            } else if let Some(p) = line.strip_prefix("#   ") {
                planned.last_mut().unwrap().push(p.to_string());
            }
        }
        assert_eq!(planned, shards, "{printed}");
    }
    let bad = Cmd::new([names[0], "-o", out.to_str().unwrap(), "--shard", "auto/2"])
        .env_remove("SLURM_ARRAY_TASK_ID")
        .run();
    assert_eq!(bad.code, 2);
    assert!(bad.stderr.contains("SLURM_ARRAY_TASK_ID"));
    Cmd::new([names[0], "-o", out.to_str().unwrap(), "--shard", "3/3"])
        .fails(2, &["does not exist"]);
}

// ---- A job directory checked, not trusted (issue 20, part 3) ----

/// A digest of each file's bytes (FNV-1a), to show inputs are unchanged.
fn checksums(paths: &[PathBuf]) -> Vec<Option<u64>> {
    paths
        .iter()
        .map(|p| {
            std::fs::read(p).ok().map(|bytes| {
                bytes.iter().fold(0xcbf29ce484222325u64, |h, &b| {
                    (h ^ b as u64).wrapping_mul(0x100000001b3)
                })
            })
        })
        .collect()
}

/// Temporary files of specconv (`.NAME.specconv-….tmp`) anywhere under `dir`.
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let (path, name) = (e.path(), e.file_name().to_string_lossy().into_owned());
        if e.file_type().is_ok_and(|t| t.is_dir()) {
            found.extend(temporaries(&path));
        } else if name.starts_with('.') && name.contains(".specconv-") && name.ends_with(".tmp") {
            found.push(path);
        }
    }
    found
}

/// Every input as it was, and no temporary file left under `dir`.
#[track_caller]
fn assert_clean(dir: &Path, inputs: &[PathBuf], sums: &[Option<u64>]) {
    assert_eq!(checksums(inputs), sums, "an input changed");
    let left = temporaries(dir);
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

/// Executables `name` with the given shell text in `dir`/bin; returns a PATH with them first.
fn fake_tools(dir: &Scratch, tools: &[(&str, &str)]) -> String {
    use std::os::unix::fs::PermissionsExt;
    let bin = dir.path("bin");
    std::fs::create_dir_all(&bin).unwrap();
    for (name, text) in tools {
        let p = bin.join(name);
        std::fs::write(&p, format!("#!/bin/sh\n{text}\n")).unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    )
}

/// Waits until the `specconv convert` (or the farm task, whose job directory is in `out`)
/// writing into `out` is stopped (SIGSTOP, state T) or, with
/// `stopped` false, runs again or has ended; fails after 60 s.
fn converting_is_stopped(out: &Path, stopped: bool) {
    let out = out.to_str().unwrap();
    let states = || -> Vec<char> {
        std::fs::read_dir("/proc")
            .unwrap()
            .filter_map(|e| {
                let dir = e.ok()?.path();
                let cmdline = std::fs::read(dir.join("cmdline")).ok()?;
                let args: Vec<&[u8]> = cmdline.split(|&b| b == 0).collect();
                let task = args.contains(&&b"farm"[..]) && args.contains(&&b"task"[..]);
                let ours = (args.contains(&&b"convert"[..]) || task)
                    && args.iter().any(|a| a.starts_with(out.as_bytes()));
                let stat = std::fs::read_to_string(dir.join("stat")).ok()?;
                // The state follows the command name, which is in parentheses.
                let state = stat.rsplit_once(") ")?.1.chars().next()?;
                ours.then_some(state)
            })
            .collect()
    };
    let start = std::time::Instant::now();
    loop {
        let now = states();
        // Resumed, it may also have ended already.
        if (!now.is_empty() || !stopped) && now.iter().all(|&s| (s == 'T') == stopped) {
            return;
        }
        assert!(
            start.elapsed().as_secs() < 60,
            "the conversion into {out} is not {} ({now:?})",
            if stopped { "stopped" } else { "running" }
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// Polls `farm collect` until no task of the job is queued or running; returns its summary.
fn wait_for(job_dir: &Path) -> Value {
    let start = std::time::Instant::now();
    loop {
        let c: Value =
            serde_json::from_str(&farm(&["collect", job_dir.to_str().unwrap(), "--json"]).stdout)
                .unwrap();
        if c["running"] == false {
            return c;
        }
        assert!(
            start.elapsed().as_secs() < 600,
            "the job never ended (hang guard)"
        );
        std::thread::sleep(std::time::Duration::from_millis(200));
    }
}

/// Starts a command with its output captured, to run beside another.
fn spawned(mut c: Command) -> std::process::Child {
    use std::process::Stdio;
    c.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    c.spawn().unwrap()
}

fn submitted_job_dir(out: &Output) -> PathBuf {
    let lines = json_lines(&out.stdout);
    assert!(!lines.is_empty(), "{}\n{}", out.stdout, out.stderr);
    PathBuf::from(lines[0]["job_dir"].as_str().unwrap())
}

#[test]
fn a_manifest_edited_to_point_outside_is_refused_and_retry_deletes_nothing_there() {
    if !cluster() {
        return;
    }
    let dir = Scratch::new("farm-outside");
    let out = dir.path("out");
    std::fs::create_dir_all(&out).unwrap();
    let (a, b) = (dir.path("a.png"), dir.path("b.png"));
    texture(&a, 24, 16, 1);
    // b is missing: its file fails, so a retry has something to do.
    let submitted = farm(&[
        "submit",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--tasks",
        "1",
        "--wait",
        "--json",
    ]);
    assert_eq!(
        submitted.code, 1,
        "{}\n{}",
        submitted.stdout, submitted.stderr
    );
    let job_dir = submitted_job_dir(&submitted);
    texture(&b, 16, 24, 2);
    let inputs = vec![a.clone(), b.clone()];
    let sums = checksums(&inputs);

    // Files outside the job: one named like an output, one like its temporary.
    let victim = dir.path("victim");
    std::fs::create_dir_all(&victim).unwrap();
    let precious = victim.join("precious.exr");
    let decoy = victim.join(".precious.exr.specconv-1-0.tmp");
    std::fs::write(&precious, b"precious").unwrap();
    std::fs::write(&decoy, b"also precious").unwrap();
    let kept = vec![precious.clone(), decoy.clone()];
    let kept_sums = checksums(&kept);

    let path = job_dir.join("manifest.json");
    let original = std::fs::read_to_string(&path).unwrap();
    let mut m: Value = serde_json::from_str(&original).unwrap();
    let k = (0..2)
        .find(|&k| m["files"][k]["input"] == b.to_str().unwrap())
        .unwrap();
    m["files"][k]["output"] = Value::from(precious.to_str().unwrap());
    std::fs::write(&path, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    for command in ["retry", "status", "collect"] {
        let run = Cmd::new(["farm", command, job_dir.to_str().unwrap()]).run();
        assert_eq!(
            checksums(&kept),
            kept_sums,
            "{command} changed a file outside the job:\n{}\n{}",
            run.stdout,
            run.stderr
        );
        run.one_error_line(2, &[precious.to_str().unwrap(), "edited or damaged"]);
    }
    assert!(
        !job_dir.join("round-1").exists(),
        "a refused retry submitted"
    );

    // A plan naming a file the manifest does not list: refused, not a panic.
    let mut m: Value = serde_json::from_str(&original).unwrap();
    m["rounds"][0]["tasks"][0] = serde_json::json!([0, 99]);
    std::fs::write(&path, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    Cmd::new(["farm", "status", job_dir.to_str().unwrap()])
        .run()
        .one_error_line(2, &["edited or damaged"]);

    // Restored, the job retries as before.
    std::fs::write(&path, &original).unwrap();
    let retried = farm(&["retry", job_dir.to_str().unwrap(), "--wait"]);
    assert_eq!(retried.code, 0, "{}\n{}", retried.stdout, retried.stderr);
    assert_eq!(checksums(&kept), kept_sums);
    std::fs::remove_file(&decoy).unwrap();
    assert_clean(&dir.0, &inputs, &sums);
}

#[test]
fn retry_while_slurm_does_not_answer_removes_no_temporary_of_a_running_task() {
    if !cluster() {
        return;
    }
    let dir = Scratch::new("farm-running");
    let out = dir.path("out");
    std::fs::create_dir_all(&out).unwrap();
    let big = dir.path("big.exr");
    noise(&big, 2048, "half");
    let inputs = vec![big.clone()];
    let sums = checksums(&inputs);
    let submitted = farm(&[
        "submit",
        big.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--tasks",
        "1",
        "--json",
    ]);
    let job_dir = submitted_job_dir(&submitted);
    let job_id = json_lines(&submitted.stdout)[0]["job_id"]
        .as_str()
        .unwrap()
        .to_string();
    let start = std::time::Instant::now();
    let writing = || temporaries(&out);
    while writing().is_empty() {
        assert!(
            start.elapsed().as_secs() < 600,
            "the task never started writing"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // Stopped mid-file, so its temporary stays while we look. slurmd stops the task after
    // scontrol returns; a resume that overtakes the stop left the task stopped for good (CI:
    // resume 61 ms after suspend, then a 600 s hang), so each is waited for.
    let task = format!("{job_id}_0");
    tool("scontrol", &["suspend", &task]);
    converting_is_stopped(&out, true);
    let tmp = writing();
    let unreachable = fake_tools(
        &dir,
        &[
            (
                "scontrol",
                "echo 'slurm_load_jobs error: Unable to contact slurm controller (connect failure)' >&2; exit 1",
            ),
            ("sacct", "echo 'sacct: error: Problem talking to the database' >&2; exit 1"),
        ],
    );
    let retried = Cmd::new(["farm", "retry", job_dir.to_str().unwrap()])
        .env("PATH", &unreachable)
        .run();
    let still: Vec<bool> = tmp.iter().map(|p| p.exists()).collect();
    tool("scontrol", &["resume", &task]);
    converting_is_stopped(&out, false);
    assert!(
        still.iter().all(|&s| s),
        "retry removed the temporary of a running task ({tmp:?}):\n{}\n{}",
        retried.stdout,
        retried.stderr
    );
    assert!(
        !job_dir.join("round-1").exists(),
        "retry submitted a running file again"
    );
    assert!(!retried.stderr.contains("panicked"), "{}", retried.stderr);
    let c = wait_for(&job_dir);
    assert_eq!(
        (c["done"].as_u64(), c["pending"].as_u64()),
        (Some(1), Some(0)),
        "{c}"
    );
    assert_clean(&dir.0, &inputs, &sums);
}

#[test]
fn a_percent_in_the_output_or_job_directory_reaches_slurm_literally() {
    if !cluster() {
        return;
    }
    let dir = Scratch::new("farm-percent");
    let inputs: Vec<PathBuf> = (0..2).map(|k| dir.path(&format!("p{k}.png"))).collect();
    for (k, p) in inputs.iter().enumerate() {
        texture(p, 16 + 8 * k, 16, k);
    }
    let sums = checksums(&inputs);
    let names: Vec<&str> = inputs.iter().map(|p| p.to_str().unwrap()).collect();
    // -o with patterns, its job directory the default one inside; then --job-dir with them.
    let out = dir.path("out%j%A_%a%%x");
    std::fs::create_dir_all(&out).unwrap();
    let job = dir.path("job%j%%");
    for extra in [vec![], vec!["--job-dir", job.to_str().unwrap()]] {
        let mut args = vec!["submit"];
        args.extend(&names);
        args.extend([
            "-o",
            out.to_str().unwrap(),
            "--tasks",
            "2",
            "--wait",
            "--json",
        ]);
        args.extend(&extra);
        let submitted = farm(&args);
        assert_eq!(
            submitted.code, 0,
            "{}\n{}",
            submitted.stdout, submitted.stderr
        );
        let job_dir = submitted_job_dir(&submitted);
        assert!(job_dir.to_str().unwrap().contains('%'));
        for t in 0..2 {
            let log = job_dir.join(format!("round-0/task-{t}.jsonl"));
            assert!(log.is_file(), "{} missing", log.display());
        }
        let status = farm(&["status", job_dir.to_str().unwrap()]);
        assert_eq!(status.code, 0, "{}", status.stdout);
        for p in &inputs {
            let o = out.join(format!(
                "{}_spectral.exr",
                p.file_stem().unwrap().to_string_lossy()
            ));
            assert!(o.is_file(), "{} missing", o.display());
        }
        // -u: the second submission skips them (two files, already converted).
        std::fs::remove_dir_all(&job_dir).unwrap();
    }
    // Nothing went to a path Slurm made by expanding the patterns.
    let mut names = dir.files();
    names.retain(|n| !n.ends_with(".png") && n != "bin");
    assert_eq!(names, ["out%j%A_%a%%x"], "{names:?}");
    assert_clean(&dir.0, &inputs, &sums);
}

#[test]
fn an_interrupted_submit_is_not_submitted_until_retry_submits_it() {
    if !cluster() {
        return;
    }
    let dir = Scratch::new("farm-interrupted");
    let out = dir.path("out");
    std::fs::create_dir_all(&out).unwrap();
    let inputs: Vec<PathBuf> = (0..3).map(|k| dir.path(&format!("i{k}.png"))).collect();
    for (k, p) in inputs.iter().enumerate() {
        texture(p, 16, 16 + 8 * k, k);
    }
    let sums = checksums(&inputs);
    let job_dir = dir.path("job");
    // sbatch that kills the submit: it dies between writing the job directory and Slurm.
    let killing = fake_tools(&dir, &[("sbatch", "kill -KILL $PPID; exit 1")]);
    let mut args = vec!["farm", "submit"];
    args.extend(inputs.iter().map(|p| p.to_str().unwrap()));
    args.extend(["-o", out.to_str().unwrap(), "--tasks", "2"]);
    args.extend(["--job-dir", job_dir.to_str().unwrap()]);
    let killed = Cmd::new(&args)
        .env("PATH", &killing)
        .command()
        .output()
        .unwrap();
    assert_eq!(
        killed.status.code(),
        None,
        "the submit was meant to be killed"
    );
    assert!(job_dir.join("manifest.json").is_file());

    let status = farm(&["status", job_dir.to_str().unwrap()]);
    assert_eq!(status.code, 1, "{}\n{}", status.stdout, status.stderr);
    assert!(status.stdout.contains("not submitted"), "{}", status.stdout);
    let collected = farm(&["collect", job_dir.to_str().unwrap(), "--json"]);
    assert_eq!(collected.code, 1, "{}", collected.stdout);
    let c: Value = serde_json::from_str(&collected.stdout).unwrap();
    assert_eq!(
        (c["done"].as_u64(), c["pending"].as_u64()),
        (Some(0), Some(3)),
        "{c}"
    );
    let text = farm(&["collect", job_dir.to_str().unwrap()]);
    assert!(text.stdout.contains("not submitted"), "{}", text.stdout);

    // Two retries at once: one submits the round, the other then finds it live (or done).
    let retry = || Cmd::new(["farm", "retry", job_dir.to_str().unwrap()]).command();
    let (one, two) = (spawned(retry()), spawned(retry()));
    let runs = [
        one.wait_with_output().unwrap(),
        two.wait_with_output().unwrap(),
    ];
    let said: Vec<String> = runs
        .iter()
        .map(|o| String::from_utf8_lossy(&o.stdout).into_owned())
        .collect();
    assert!(runs.iter().all(|o| o.status.code() == Some(0)), "{said:?}");
    assert_eq!(
        said.iter().filter(|s| s.contains("submitted job")).count(),
        1,
        "{said:?}"
    );
    assert!(!job_dir.join("round-2").exists(), "{said:?}");
    let c = wait_for(&job_dir);
    assert_eq!(
        (c["done"].as_u64(), c["pending"].as_u64()),
        (Some(3), Some(0)),
        "{c}"
    );
    assert_clean(&dir.0, &inputs, &sums);
}

#[test]
fn two_concurrent_submits_into_one_output_directory_do_not_both_succeed() {
    if !cluster() {
        return;
    }
    let dir = Scratch::new("farm-twice");
    let out = dir.path("out");
    std::fs::create_dir_all(&out).unwrap();
    let inputs: Vec<PathBuf> = (0..2).map(|k| dir.path(&format!("t{k}.png"))).collect();
    for (k, p) in inputs.iter().enumerate() {
        texture(p, 16, 16, k);
    }
    let sums = checksums(&inputs);
    // Submitted held, so the first job is certainly live while the second looks.
    let holding = fake_tools(&dir, &[("sbatch", "exec /usr/bin/sbatch --hold \"$@\"")]);
    let submit = |job: &str| {
        let mut args = vec!["farm", "submit"];
        args.extend(inputs.iter().map(|p| p.to_str().unwrap()));
        args.extend(["-o", out.to_str().unwrap(), "--tasks", "1", "--json"]);
        let job_dir = dir.path(job);
        args.extend(["--job-dir", job_dir.to_str().unwrap()]);
        Cmd::new(&args).env("PATH", &holding).command()
    };
    let (one, two) = (spawned(submit("job1")), spawned(submit("job2")));
    let (one, two) = (
        one.wait_with_output().unwrap(),
        two.wait_with_output().unwrap(),
    );
    let runs = [(one, "job1"), (two, "job2")];
    let ok: Vec<_> = runs
        .iter()
        .filter(|(o, _)| o.status.code() == Some(0))
        .collect();
    let refused: Vec<_> = runs
        .iter()
        .filter(|(o, _)| o.status.code() != Some(0))
        .collect();
    let ids: Vec<String> = ok
        .iter()
        .map(|(o, _)| {
            json_lines(&String::from_utf8_lossy(&o.stdout))[0]["job_id"]
                .as_str()
                .unwrap()
                .to_string()
        })
        .collect();
    for id in &ids {
        tool("scontrol", &["release", id]);
    }
    assert_eq!(ok.len(), 1, "both submits succeeded: {ids:?}");
    let (winner, loser) = (ok[0], refused[0]);
    let stderr = String::from_utf8_lossy(&loser.0.stderr);
    assert_eq!(loser.0.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains(dir.path(winner.1).to_str().unwrap()) && stderr.contains(&ids[0]),
        "{stderr}"
    );
    assert!(!dir.path(loser.1).join("manifest.json").exists());
    let c = wait_for(&dir.path(winner.1));
    assert_eq!(c["done"].as_u64(), Some(2), "{c}");
    // A finished job does not block the next submission.
    let mut args = vec!["farm", "submit"];
    args.extend(inputs.iter().map(|p| p.to_str().unwrap()));
    args.extend(["-o", out.to_str().unwrap(), "--tasks", "1", "--wait"]);
    let third = Cmd::new(&args).run();
    assert_eq!(third.code, 0, "{}\n{}", third.stdout, third.stderr);
    assert_clean(&dir.0, &inputs, &sums);
}

/// An OCIO config with a colour space the built-in configs lack.
fn pinned_config(dir: &Scratch, name: &str) -> PathBuf {
    dir.write(
        name,
        "ocio_profile_version: 2.1\n\
         roles:\n  default: ACES2065-1\n  aces_interchange: ACES2065-1\n  scene_linear: farm_pinned\n\
         file_rules:\n  - !<Rule> {name: Default, colorspace: default}\n\
         displays:\n  Monitor:\n    - !<View> {name: Raw, colorspace: ACES2065-1}\n\
         colorspaces:\n  - !<ColorSpace>\n    name: ACES2065-1\n\
         \x20 - !<ColorSpace>\n    name: farm_pinned\n    to_scene_reference: !<BuiltinTransform> {style: ACEScg_to_ACES2065-1}\n",
    )
}

#[test]
fn the_ocio_config_and_model_submit_checked_are_the_ones_every_task_uses() {
    if !cluster() {
        return;
    }
    let dir = Scratch::new("farm-ocio");
    let config = pinned_config(&dir, "pinned.ocio");
    let inputs: Vec<PathBuf> = (0..2).map(|k| dir.path(&format!("c{k}.png"))).collect();
    for (k, p) in inputs.iter().enumerate() {
        texture(p, 16, 16, k);
    }
    let sums = checksums(&inputs);
    // $OCIO and $SPECCONV_MODEL at submit; the nodes get none (SBATCH_EXPORT=NONE) or others.
    for (k, export) in [
        "NONE",
        "NONE,OCIO=/nonexistent/config.ocio,SPECCONV_MODEL=broad",
    ]
    .iter()
    .enumerate()
    {
        let out = dir.path(&format!("out{k}"));
        std::fs::create_dir_all(&out).unwrap();
        let mut args = vec!["farm", "submit"];
        args.extend(inputs.iter().map(|p| p.to_str().unwrap()));
        args.extend(["-o", out.to_str().unwrap(), "--tasks", "2", "--wait"]);
        args.extend(["--colorspace", "farm_pinned"]);
        let job_dir = dir.path(&format!("job{k}"));
        args.extend(["--job-dir", job_dir.to_str().unwrap()]);
        let run = Cmd::new(&args)
            .env("OCIO", &config)
            .env("SPECCONV_MODEL", "paper")
            .env("SBATCH_EXPORT", export)
            .run();
        assert_eq!(run.code, 0, "{export}:\n{}\n{}", run.stdout, run.stderr);
        for p in &inputs {
            let o = out.join(format!(
                "{}_spectral.exr",
                p.file_stem().unwrap().to_string_lossy()
            ));
            let h = tool("exrheader", &[o.to_str().unwrap()]);
            assert!(h.contains("pinned.ocio"), "{export}: {h}");
            assert!(h.contains("built-in paper (8 clusters"), "{export}: {h}");
        }
    }
    assert_clean(&dir.0, &inputs, &sums);
}

/// The model in force at submit is recorded in the manifest (the plan says it): the built-in
/// default by name, or the site's; one that cannot be used is refused before anything is written.
#[test]
fn submit_records_the_model_in_force() {
    let dir = Scratch::new("farm-model");
    let input = dir.path("a.png");
    texture(&input, 8, 8, 0);
    let out = dir.path("out");
    std::fs::create_dir_all(&out).unwrap();
    let args = [
        "farm",
        "submit",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--tasks",
        "1",
        "--dry-run",
    ];
    let plain = Cmd::new(args).run();
    assert!(
        plain.ok().contains("# options: model=open"),
        "{}",
        plain.stdout
    );
    let site = Cmd::new(args).env("SPECCONV_MODEL", "paper").run();
    assert!(
        site.ok().contains("# options: model=paper"),
        "{}",
        site.stdout
    );
    let named = Cmd::new(args)
        .args(["--model", "broad"])
        .env("SPECCONV_MODEL", "paper")
        .run();
    assert!(
        named.ok().contains("# options: model=broad"),
        "{}",
        named.stdout
    );
    Cmd::new(args)
        .env("SPECCONV_MODEL", "nonesuch")
        .fails(2, &["$SPECCONV_MODEL", "'nonesuch'"]);
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 0);
}

#[test]
fn retry_ocio_reaches_the_new_rounds_script() {
    if !cluster() {
        return;
    }
    let dir = Scratch::new("farm-retry-ocio");
    let out = dir.path("out");
    std::fs::create_dir_all(&out).unwrap();
    let (first, second) = (
        pinned_config(&dir, "first.ocio"),
        pinned_config(&dir, "second.ocio"),
    );
    let (a, b) = (dir.path("a.png"), dir.path("b.png"));
    texture(&a, 16, 16, 0);
    let job_dir = dir.path("job");
    let submitted = Cmd::new([
        "--ocio",
        first.to_str().unwrap(),
        "farm",
        "submit",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--tasks",
        "1",
        "--wait",
        "--job-dir",
        job_dir.to_str().unwrap(),
    ])
    .run();
    assert_eq!(
        submitted.code, 1,
        "b is missing:\n{}\n{}",
        submitted.stdout, submitted.stderr
    );
    texture(&b, 16, 24, 1);
    let inputs = vec![a.clone(), b.clone()];
    let sums = checksums(&inputs);
    let retried = Cmd::new([
        "--ocio",
        second.to_str().unwrap(),
        "farm",
        "retry",
        job_dir.to_str().unwrap(),
        "--wait",
    ])
    .env("SBATCH_EXPORT", "NONE")
    .run();
    assert_eq!(retried.code, 0, "{}\n{}", retried.stdout, retried.stderr);
    // The new round's tasks read the config from the manifest, which retry rewrote.
    let manifest = std::fs::read_to_string(job_dir.join("manifest.json")).unwrap();
    let manifest: serde_json::Value = serde_json::from_str(&manifest).unwrap();
    assert_eq!(manifest["ocio"], second.to_str().unwrap(), "{manifest}");
    let h = tool("exrheader", &[out.join("b_spectral.exr").to_str().unwrap()]);
    assert!(h.contains("second.ocio"), "{h}");
    let h = tool("exrheader", &[out.join("a_spectral.exr").to_str().unwrap()]);
    assert!(h.contains("first.ocio"), "{h}");
    assert_clean(&dir.0, &inputs, &sums);
}

#[test]
fn outputs_by_template_pass_the_job_directorys_own_check() {
    // The farm checks each output against the template as it reads the manifest; submit runs
    // that check first, so a template convert expands differently would be refused here.
    let dir = Scratch::new("farm-template");
    std::fs::create_dir_all(dir.path("lib/wood")).unwrap();
    std::fs::create_dir_all(dir.path("lib/metal")).unwrap();
    std::fs::create_dir_all(dir.path("lib/o2")).unwrap();
    texture(&dir.path("lib/wood/a.png"), 16, 16, 0);
    texture(&dir.path("lib/metal/b.png"), 16, 16, 1);
    let inputs = vec![dir.path("lib/wood/a.png"), dir.path("lib/metal/b.png")];
    let sums = checksums(&inputs);
    for template in [
        "{dir}/../o2/{stem}.exr",
        "lib/o2/{name}.exr",
        "./lib/./o2/{stem}_s.exr",
    ] {
        let dry = Cmd::new([
            "farm",
            "submit",
            "lib/wood/a.png",
            "./lib/metal/../metal/b.png",
            "--output-template",
            template,
            "--job-dir",
            "job",
            "--tasks",
            "2",
            "--dry-run",
        ])
        .current_dir(&dir.0)
        .run();
        assert_eq!(dry.code, 0, "{template}:\n{}\n{}", dry.stdout, dry.stderr);
        assert!(
            dry.stdout
                .contains(&format!("# outputs: template {template}")),
            "{}",
            dry.stdout
        );
    }
    assert!(!dir.path("job").exists());
    assert_clean(&dir.0, &inputs, &sums);
}

#[test]
fn a_job_directory_whose_manifest_is_no_manifest_is_refused_with_status_2() {
    // Needs no cluster: the manifest is refused before Slurm is asked (docs/farm.md: exit
    // status 2, one line naming the path, nothing changed).
    let dir = Scratch::new("farm-not-a-manifest");
    let job = |name: &str| {
        let j = dir.path(name);
        std::fs::create_dir_all(&j).unwrap();
        j
    };
    let layout = job("layout");
    std::fs::write(
        layout.join("manifest.json"),
        r#"{"format": 2, "files": [], "rounds": []}"#,
    )
    .unwrap();
    let text = job("text");
    std::fs::write(text.join("manifest.json"), "not json").unwrap();
    let fifo = job("fifo");
    assert!(Command::new("mkfifo")
        .arg(fifo.join("manifest.json"))
        .status()
        .unwrap()
        .success());
    let zero = job("zero");
    std::os::unix::fs::symlink("/dev/zero", zero.join("manifest.json")).unwrap();
    let link = job("link");
    std::os::unix::fs::symlink(layout.join("manifest.json"), link.join("manifest.json")).unwrap();
    let empty = job("empty");
    let cases = [
        (&layout, "manifest.json"),
        (&text, "manifest.json"),
        (&fifo, "a FIFO (named pipe), not a regular file"),
        (&zero, "a symbolic link, not a regular file"),
        (&link, "a symbolic link, not a regular file"),
        (&empty, "no such file"),
    ];
    for (job_dir, said) in cases {
        for command in ["status", "collect", "retry"] {
            let before = dir.files();
            let out = Cmd::new(["farm", command])
                .arg(job_dir)
                .run_within(std::time::Duration::from_secs(20));
            out.one_error_line(2, &[job_dir.to_str().unwrap(), said]);
            assert_eq!(
                dir.files(),
                before,
                "{command} {job_dir:?} changed something"
            );
        }
    }
}
