//! The plan of a batch as a careless or hostile user meets it (issue 30): shards that run in
//! any order or side by side, two inputs aimed at one output, an output that is an input under
//! another name. The rules are the library's (specconv_conversion::plan); these run the binary.

use crate::convert::testdata;
use crate::runner::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Five small inputs of different sizes (the split weighs pixels), each name its own stem.
fn inputs(s: &Scratch) -> Vec<PathBuf> {
    [
        "srgb8.png",
        "rgb16.png",
        "photo.jpg",
        "rgba16.png",
        "srgba8.png",
    ]
    .iter()
    .enumerate()
    .map(|(k, name)| {
        let ext = Path::new(name).extension().unwrap().to_str().unwrap();
        let p = s.path(&format!("t{k}.{ext}"));
        std::fs::copy(testdata(name), &p).unwrap();
        p
    })
    .collect()
}

/// `convert INPUTS -o OUT --shard I/N --json --mip 0`, without -u or --force.
fn shard(inputs: &[PathBuf], out: &Path, i: usize, n: usize) -> Cmd {
    Cmd::new(["convert"])
        .args(inputs)
        .arg("-o")
        .arg(out)
        .args(["--json", "--mip", "0", "--progress", "never"])
        .args(["--shard", &format!("{i}/{n}")])
}

/// The inputs a run's records say it converted; every record `ok`.
#[track_caller]
fn converted(out: &Output) -> Vec<String> {
    out.json_lines()
        .iter()
        .map(|r| {
            assert_eq!(r["status"], "ok", "{r}");
            r["input"].as_str().unwrap().to_string()
        })
        .collect()
}

/// How many times each input was converted, over several runs.
fn tally(runs: &[Vec<String>]) -> BTreeMap<String, usize> {
    let mut seen = BTreeMap::new();
    for input in runs.iter().flatten() {
        *seen.entry(input.clone()).or_insert(0) += 1;
    }
    seen
}

#[track_caller]
fn each_once(runs: &[Vec<String>], inputs: &[PathBuf]) {
    let expected: BTreeMap<String, usize> = inputs
        .iter()
        .map(|p| (p.to_str().unwrap().to_string(), 1))
        .collect();
    assert_eq!(tally(runs), expected, "{runs:?}");
}

#[test]
fn shards_in_any_order_convert_every_input_exactly_once_without_update_or_force() {
    let s = Scratch::new("plans-shard-order");
    let inputs = inputs(&s);
    let orders = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    for (k, order) in orders.iter().enumerate() {
        let out = s.path(&format!("out{k}"));
        std::fs::create_dir_all(&out).unwrap();
        let runs: Vec<Vec<String>> = order
            .iter()
            .map(|&i| converted(&shard(&inputs, &out, i, 3).ok()))
            .collect();
        each_once(&runs, &inputs);
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), inputs.len());
        // A shard run again still finds its own outputs, and only its own, in its way.
        let again = shard(&inputs, &out, order[0], 3).fails(2, &["exists"]);
        let named = again.stderr.split(" exists").next().unwrap().to_string();
        let own: Vec<String> = runs[0]
            .iter()
            .map(|i| {
                let stem = Path::new(i).file_stem().unwrap().to_str().unwrap();
                out.join(format!("{stem}_spectral.exr"))
                    .to_str()
                    .unwrap()
                    .to_string()
            })
            .collect();
        assert!(
            own.iter().any(|o| named.ends_with(o.as_str())),
            "{named} is not one of {own:?}"
        );
        // With -u every shard skips what it made.
        for i in 0..3 {
            let records = shard(&inputs, &out, i, 3).arg("-u").ok().json_lines();
            assert!(
                records.iter().all(|r| r["status"] == "skipped"),
                "{records:?}"
            );
        }
    }
    no_temporaries(&s.0);
}

/// Starts a shard run, its output captured.
fn start(cmd: Cmd) -> std::process::Child {
    cmd.command()
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits for a started run; asserts success; the inputs it converted.
#[track_caller]
fn finish(child: std::process::Child) -> Vec<String> {
    let o = child.wait_with_output().unwrap();
    let out = Output {
        code: o.status.code().unwrap(),
        stdout: String::from_utf8_lossy(&o.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
    };
    out.ok();
    converted(&out)
}

/// Outputs published in `dir` (not temporaries).
fn published(dir: &Path) -> usize {
    std::fs::read_dir(dir)
        .unwrap()
        .filter(|e| {
            let name = e.as_ref().unwrap().file_name();
            name.to_string_lossy().ends_with("_spectral.exr")
        })
        .count()
}

#[test]
fn shards_side_by_side_convert_every_input_exactly_once() {
    let s = Scratch::new("plans-shard-parallel");
    let mut inputs = inputs(&s);
    // One larger texture, so that its shard is still at work while the others start.
    let big = s.path("big.png");
    noise(&big, 384, "uint8");
    inputs.push(big);
    // All three started at once, as GNU parallel or a farm's array starts them.
    let out = s.path("at-once");
    std::fs::create_dir_all(&out).unwrap();
    let children: Vec<_> = (0..3).map(|i| start(shard(&inputs, &out, i, 3))).collect();
    let runs: Vec<Vec<String>> = children.into_iter().map(finish).collect();
    each_once(&runs, &inputs);
    assert_eq!(published(&out), inputs.len());
    // One shard ahead: the others start once it has published an output, while it may
    // still be converting (a scheduler's uneven start).
    for first in 0..3 {
        let out = s.path(&format!("after-{first}"));
        std::fs::create_dir_all(&out).unwrap();
        let mut ahead = start(shard(&inputs, &out, first, 3));
        let waited = std::time::Instant::now();
        while published(&out) == 0 && ahead.try_wait().unwrap().is_none() {
            assert!(
                waited.elapsed().as_secs() < 120,
                "no output from shard {first}"
            );
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        let others: Vec<_> = (0..3)
            .filter(|&i| i != first)
            .map(|i| start(shard(&inputs, &out, i, 3)))
            .collect();
        let mut runs = vec![finish(ahead)];
        runs.extend(others.into_iter().map(finish));
        each_once(&runs, &inputs);
        assert_eq!(published(&out), inputs.len());
    }
    no_temporaries(&s.0);
}

#[test]
fn two_inputs_for_one_output_are_both_named_in_every_shard() {
    let s = Scratch::new("plans-collide");
    let png = s.path("brick.png");
    std::fs::copy(testdata("srgb8.png"), &png).unwrap();
    let tx = s.path("brick.tx");
    std::fs::copy(testdata("srgba8.tx"), &tx).unwrap();
    std::fs::create_dir_all(s.path("conv")).unwrap();
    let line = "brick.png and brick.tx would both write conv/brick_spectral.exr (an output \
                template with {ext} or {name} separates them, such as \
                conv/{stem}_{ext}_spectral.exr); give each input its own output";
    Cmd::new(["convert", "brick.png", "brick.tx", "-o", "conv"])
        .current_dir(&s.0)
        .refused(&s, 2, &[line]);
    // The two inputs fall in different shards: each shard refuses the whole plan.
    for i in 0..2 {
        Cmd::new(["convert", "brick.png", "brick.tx", "-o", "conv", "--force"])
            .args(["--shard", &format!("{i}/2")])
            .current_dir(&s.0)
            .refused(&s, 2, &[line]);
    }
    // One input given twice, from standard input.
    Cmd::new(["convert", "-", "-o", "conv"])
        .stdin("brick.png\nbrick.png\n")
        .current_dir(&s.0)
        .refused(&s, 2, &["brick.png is given twice"]);
    // Spelled apart, one file: both inputs and both spellings.
    Cmd::new(["convert", "brick.png", "brick.tx"])
        .args(["--output-template", "conv/../conv/{dir}/x.exr"])
        .current_dir(&s.0)
        .refused(&s, 2, &["brick.png and brick.tx would both write"]);
    assert!(std::fs::read_dir(s.path("conv")).unwrap().next().is_none());
    // The template field the message names separates them.
    Cmd::new(["convert", "brick.png", "brick.tx", "--mip", "0"])
        .args(["--output-template", "conv/{stem}_{ext}_spectral.exr"])
        .current_dir(&s.0)
        .ok();
    for name in ["brick_png_spectral.exr", "brick_tx_spectral.exr"] {
        assert!(s.path("conv").join(name).is_file(), "{name}");
    }
}

#[test]
fn an_output_that_is_an_input_is_refused_by_any_name_and_in_every_shard() {
    let s = Scratch::new("plans-identity");
    let x = s.path("x.exr");
    std::fs::copy(testdata("half_tiled_alpha.exr"), &x).unwrap();
    let y = s.path("y.png");
    std::fs::copy(testdata("srgb8.png"), &y).unwrap();
    std::os::unix::fs::symlink("y.png", s.path("link.exr")).unwrap();
    std::fs::hard_link(&y, s.path("hard.exr")).unwrap();
    std::fs::create_dir_all(s.path("sub")).unwrap();
    let before: Vec<Vec<u8>> = [&x, &y].iter().map(|p| std::fs::read(p).unwrap()).collect();
    for flags in [&[][..], &["--force"], &["-u"], &["-u", "--force"]] {
        // INPUT OUTPUT: a symbolic link to it, a hard link to it, `./` and `..` spellings.
        for (input, output) in [
            ("y.png", "link.exr"),
            ("y.png", "hard.exr"),
            ("x.exr", "./x.exr"),
            ("x.exr", "sub/../x.exr"),
        ] {
            Cmd::new(["convert", input, output])
                .args(flags)
                .current_dir(&s.0)
                .refused(&s, 2, &["is the input"]);
        }
        // A batch whose template names another input through a link, in whichever shard.
        for shard in [None, Some("0/2"), Some("1/2")] {
            Cmd::new(["convert", "x.exr", "y.png"])
                .args(["--output-template", "{dir}/sub/../link.exr"])
                .args(flags)
                .args(shard.map(|s| ["--shard", s]).into_iter().flatten())
                .current_dir(&s.0)
                .refused(&s, 2, &["is the input"]);
        }
    }
    let after: Vec<Vec<u8>> = [&x, &y].iter().map(|p| std::fs::read(p).unwrap()).collect();
    assert!(after == before, "an input changed");
    no_temporaries(&s.0);
}

#[test]
fn one_output_for_a_list_of_inputs_is_refused_not_cut_short() {
    let s = Scratch::new("plans-one-output");
    let inputs = inputs(&s);
    let list: String = inputs[..2]
        .iter()
        .map(|p| format!("{}\n", p.display()))
        .collect();
    Cmd::new(["convert", "-", "one.exr"])
        .stdin(list)
        .current_dir(&s.0)
        .refused(&s, 2, &["2 inputs and one output one.exr"]);
}

/// The `stat`-family system calls of `binary ARGS < stdin` (`strace -f -c`), and its exit
/// status.
fn stat_calls(args: &[&std::ffi::OsStr], stdin: &Path, dir: &Scratch) -> (usize, i32) {
    let log = dir.path("strace.log");
    let out = std::process::Command::new("strace")
        .args(["-f", "-c", "-o"])
        .arg(&log)
        .arg(binary())
        .args(args)
        .stdin(std::fs::File::open(stdin).unwrap())
        .output()
        .unwrap_or_else(|e| panic!("strace must be installed (.ci/run installs it): {e}"));
    let log = std::fs::read_to_string(&log).unwrap_or_else(|e| {
        panic!(
            "strace wrote no log ({e}); can it trace here (ptrace)?\n{}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    // Columns: % time, seconds, usecs/call, calls, [errors,] syscall.
    let calls = log
        .lines()
        .filter_map(|l| {
            let cols: Vec<&str> = l.split_whitespace().collect();
            let name = *cols.last()?;
            let stat = ["statx", "newfstatat", "stat", "lstat", "fstat", "fstatat64"];
            stat.contains(&name)
                .then(|| cols.get(3)?.parse::<usize>().ok())?
        })
        .sum();
    (calls, out.status.code().unwrap_or(-1))
}

/// `n` input paths, half small PNGs in one folder of `dir` and half missing, as a list file.
fn half_missing(dir: &Scratch, n: usize) -> (PathBuf, Vec<PathBuf>) {
    let folder = dir.path("in");
    std::fs::create_dir_all(&folder).unwrap();
    let png = std::fs::read(testdata("srgb8.png")).unwrap();
    let inputs: Vec<PathBuf> = (0..n)
        .map(|k| {
            let p = folder.join(format!("t{k}.png"));
            if k % 2 == 0 {
                std::fs::write(&p, &png).unwrap();
            }
            p
        })
        .collect();
    let list: String = inputs
        .iter()
        .map(|p| format!("{}\n", p.display()))
        .collect();
    (dir.write("list", &list), inputs)
}

/// Checking a list of inputs is linear (issue 31: 2,500 names took 8.5 s and 1.7 million
/// `statx`, 10,000 took 172 s). 1,000 inputs on standard input, half of them missing, into a
/// folder that holds the last one's output already: the whole plan is checked (each output
/// compared with every input as files) and the output refused, in at most 6 `stat` calls per
/// input (5 now: each of its two output names once, `STEM_spectral.exr` and a data copy's
/// `STEM_data.exr`, each input once as an output exists, each name's existence). Every output
/// was compared with every input before: millions.
#[test]
fn a_list_of_inputs_is_checked_in_a_few_stat_calls_per_input() {
    let s = Scratch::new("plans-linear");
    let n = 1000;
    let (list, _) = half_missing(&s, n);
    let out = s.path("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join(format!("t{}_spectral.exr", n - 1)), b"not ours").unwrap();
    let (calls, code) = stat_calls(&["-".as_ref(), "-o".as_ref(), out.as_os_str()], &list, &s);
    eprintln!("{n} inputs: {calls} stat calls");
    assert_eq!(code, 2, "the existing output is refused");
    assert!(
        calls <= 6 * n + 100,
        "{calls} stat calls for {n} inputs: checking a plan is no longer linear"
    );
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        1,
        "nothing written"
    );
}

/// A batch of missing inputs looks at each output name three times in all: the plan's check
/// (kind and file), the command's check of existing outputs, and the batch's own check before
/// it writes, which takes existence from its look at the name (it looked twice before: 9
/// calls an input). Each input then fails on its own, in one more call; the rest (the model,
/// the config) is a fixed few hundred.
#[test]
fn a_batch_of_missing_inputs_looks_at_each_output_name_three_times() {
    let s = Scratch::new("plans-missing");
    let n = 1000;
    let list = s.write(
        "list",
        &(0..n)
            .map(|k| format!("{}\n", s.path(&format!("gone/t{k}.png")).display()))
            .collect::<String>(),
    );
    let out = s.path("out");
    std::fs::create_dir_all(&out).unwrap();
    let (calls, code) = stat_calls(&["-".as_ref(), "-o".as_ref(), out.as_os_str()], &list, &s);
    eprintln!("{n} missing inputs: {calls} stat calls");
    assert_eq!(code, 1, "every input fails on its own");
    assert!(
        calls <= 7 * n + n / 2,
        "{calls} stat calls for {n} missing inputs: an output name is looked at more than thrice"
    );
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        0,
        "nothing written"
    );
}

/// `farm submit - --dry-run` plans, weighs (reads each input's header) and prints 1,000 inputs
/// of a list, half missing, in at most 8 `stat` calls per input (OpenImageIO itself makes 3 for
/// each PNG it opens); before, millions.
#[test]
fn farm_submit_plans_a_list_in_a_few_stat_calls_per_input() {
    let s = Scratch::new("plans-linear-farm");
    let n = 1000;
    let (list, inputs) = half_missing(&s, n);
    let out = s.path("out");
    std::fs::create_dir_all(&out).unwrap();
    let args = ["farm", "submit", "-", "--tasks", "4", "--dry-run", "-o"];
    let mut args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_ref()).collect();
    args.push(out.as_os_str());
    let (calls, code) = stat_calls(&args, &list, &s);
    eprintln!("farm, {n} inputs: {calls} stat calls");
    assert_eq!(code, 0);
    assert!(
        calls <= 8 * n + 500,
        "{calls} stat calls for {n} inputs: planning a farm job is no longer linear"
    );
    // Every input is in the printed plan, each once, and nothing was written.
    let printed = Cmd::new(["farm", "submit", "-", "--tasks", "4", "--dry-run", "-o"])
        .arg(&out)
        .stdin(std::fs::read(&list).unwrap())
        .ok();
    let listed: Vec<&str> = printed
        .stdout
        .lines()
        .filter_map(|l| l.strip_prefix("#   "))
        .collect();
    assert_eq!(listed.len(), n, "{}", printed.stdout);
    for input in &inputs {
        assert!(
            listed.contains(&input.to_str().unwrap()),
            "{}",
            input.display()
        );
    }
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        0,
        "nothing written"
    );
}

/// Issue 56, item 6: `convert -o DIR` and `expand -o DIR` make DIR (and the folders above it)
/// as `asset -o` does; a plan refused after all (two inputs aimed at one output) leaves no
/// folder behind; `-o` naming a file is refused, the file untouched.
#[test]
fn dash_o_makes_its_directory_as_asset_does() {
    let s = Scratch::new("plans-make-dir");
    let png = s.path("a.png");
    std::fs::copy(testdata("srgb8.png"), &png).unwrap();
    let made = s.path("new/deeper");
    Cmd::new(["convert", "-q"])
        .arg(&png)
        .arg("-o")
        .arg(&made)
        .ok();
    assert!(made.join("a_spectral.exr").is_file());
    let compact = s.path("a_compact.exr");
    Cmd::convert(&png, &compact)
        .args(["--layout", "compact"])
        .ok();
    let expanded = s.path("expanded/here");
    Cmd::new(["expand", "-q"])
        .arg(&compact)
        .arg("-o")
        .arg(&expanded)
        .ok();
    assert!(expanded.join("a_compact_spectral.exr").is_file());
    // Two inputs of one stem into one folder: refused, and the folder not left behind.
    let other = s.path("b");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::copy(testdata("srgb8.png"), other.join("a.png")).unwrap();
    let refused = s.path("never/made");
    let out = Cmd::new(["convert", "-q"])
        .arg(&png)
        .arg(other.join("a.png"))
        .arg("-o")
        .arg(&refused)
        .run();
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(!s.path("never").exists(), "{}", out.stderr);
    // A file given as the directory.
    let file = s.write("notes.txt", "mine");
    Cmd::new(["convert", "-q"])
        .arg(&png)
        .arg("-o")
        .arg(&file)
        .fails(2, &["notes.txt", "not a directory"]);
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "mine");
}

/// DESIGN, "up to date means same bytes": the settings tag starts with the library's numerical
/// rules (`rules=N`), so a file written by a version whose rules differ (here: the tag of a
/// file from before the word, rewritten by oiiotool) is converted again by `-u`; the same
/// file with the tag as written is skipped.
#[test]
fn dash_u_rebuilds_what_other_numerical_rules_wrote() {
    let s = Scratch::new("plans-rules");
    let png = s.path("a.png");
    std::fs::copy(testdata("srgb8.png"), &png).unwrap();
    let out = s.path("a_spectral.exr");
    Cmd::new(["convert", "-q"]).arg(&png).arg(&out).ok();
    let status = || {
        let lines = Cmd::new(["convert", "-u", "--json"])
            .arg(&png)
            .arg(&out)
            .ok()
            .json_lines();
        lines[0]["status"].as_str().unwrap().to_string()
    };
    assert_eq!(status(), "skipped");
    let info = tool("oiiotool", &["--info", "-v", out.to_str().unwrap()]);
    let tag = info
        .lines()
        .find_map(|l| l.trim().strip_prefix("specconvSettings: "))
        .expect("the settings tag")
        .trim_matches('"')
        .to_string();
    assert!(tag.starts_with("rules="), "{tag}");
    let rewrite = |value: &str| {
        let other = s.path("rewritten.exr");
        tool(
            "oiiotool",
            &[
                out.to_str().unwrap(),
                "--sattrib",
                "specconvSettings",
                value,
                "-o",
                other.to_str().unwrap(),
            ],
        );
        std::fs::rename(&other, &out).unwrap();
    };
    // The control: rewritten by oiiotool with its own tag, still up to date.
    rewrite(&tag);
    assert_eq!(status(), "skipped");
    rewrite(tag.split_once(' ').unwrap().1);
    assert_eq!(status(), "ok");
}
