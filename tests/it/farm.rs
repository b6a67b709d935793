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
    tool(
        "oiiotool",
        &[
            "--pattern",
            "noise:min=0:max=1",
            "2048x2048",
            "3",
            "-d",
            "half",
            "-o",
            big.to_str().unwrap(),
        ],
    );
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
