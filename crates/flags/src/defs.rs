//! Every command's own flags, each defined once: the commands list which they take
//! ([`crate::args!`]); the conversion's options are the library's ([`crate::OptionArgs`]).
//! A long name several definitions share means something else in each command, and a test of
//! the command line says what.

use crate::Flag;
use clap::builder::ValueParser;
use clap::value_parser;
use specconv_evaluation::eval::SHIFT_ILLUMINANTS;
use specconv_spectral::baselines::jakob;
use specconv_spectral::otsu2018::model::BUILTIN;
use specconv_spectral::otsu2018::train::SMALLEST_CLUSTER;
use specconv_spectral::TrainOptions;

/// The most interreflections `preview --bounces` takes.
pub const MAX_BOUNCES: u32 = 100;

/// Defines each flag, and [`ALL`], every one of them.
macro_rules! defs {
    ($($(#[doc = $doc:literal])* $name:ident: $flag:expr;)*) => {
        $($(#[doc = $doc])* pub const $name: Flag = $flag;)*

        /// Every flag defined here, for the tests that hold the commands to them.
        pub const ALL: &[&Flag] = &[$(&$name),*];
    };
}

/// `train --min-cluster-size`: at least the smallest cluster a model can have.
fn min_cluster_size(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if n >= SMALLEST_CLUSTER => Ok(n),
        _ => Err(format!(
            "must be a whole number ≥ {SMALLEST_CLUSTER}: three principal components need four spectra"
        )),
    }
}

/// `eval --model`'s help, naming the built-in models.
fn eval_model_help() -> String {
    let names: Vec<&str> = BUILTIN.iter().map(|b| b.name).collect();
    format!(
        "A built-in model by name ({}: `specconv models` lists them) or a model file from \
         `specconv train`; when absent, the site default ${}, else {}",
        names.join(", "),
        specconv_conversion::models::MODEL_ENV,
        names[0]
    )
}

defs! {
    /// asset.
    ASSET_STAGE: Flag::place("stage", "STAGE", "The USD stage, or a MaterialX document");

    /// asset.
    ASSET_OUTPUT: Flag::long("output", "output", "The output directory (made if missing); nothing is written outside it").short('o').value("DIR").required();

    /// asset.
    ASSET_DRY_RUN: Flag::long("dry_run", "dry-run", "Print each texture's decision (and its output) without converting or writing anything");

    /// asset.
    ASSET_VERBOSE: Flag::long("verbose", "verbose", "Say more: each texture's decision before converting").short('v');

    /// colorspaces, simulate.
    JSON_INSTEAD_OF_TEXT: Flag::long("json", "json", "Print one JSON object instead of text");

    /// convert.
    CONVERT_PATHS: Flag::place("paths", "INPUT… [OUTPUT]", "Input textures, then the output file when converting one; `-` reads input paths from \
        standard input, one per line. A UDIM pattern (`wood.<UDIM>.png`, `<udim>` or `%(UDIM)d` in \
        the file name) stands for the tiles that exist, in tile order; converting one pattern, \
        name the output with the token too (`wood_spectral.<UDIM>.exr`)").required();

    /// convert.
    CONVERT_OUTPUT: Flag::long("output", "output", "Write every output into this directory, as STEM_spectral.exr (a data texture written \
        through by --data copy as STEM_data.exr)").short('o').value("DIR").conflicts(&["output_template"]);

    /// convert.
    CONVERT_OUTPUT_TEMPLATE: Flag::long("output_template", "output-template", "Output path for each input; {dir}, {stem}, {name} and {ext} are the input's directory, \
        name without extension, file name and extension, {udim} its UDIM tile number (1001…), \
        {tile} the same tile as u1_v1 ('{dir}/{stem}_{ext}_spectral.exr' keeps brick.png and \
        brick.tx apart) and {role} 'spectral', or 'data' for a data texture written through \
        (without {role} both are one name). With {udim} or {tile}, {stem} leaves the tile number \
        out: '{dir}/{stem}_spectral.{udim}.exr' makes wood_spectral.1001.exr of wood.1001.png. Any \
        other {field} is refused before anything is written").value("TEMPLATE");

    /// convert.
    CONVERT_SHARD: Flag::long("shard", "shard", "Convert only shard I of N (`I/N`, I from 0), or `auto/N` with I from $SLURM_ARRAY_TASK_ID: \
        inputs split by pixel count, the same plan on every run and as `farm submit`, so N runs \
        given the same inputs convert each exactly once").value("I/N");

    /// convert.
    CONVERT_VERBOSE: Flag::long("verbose", "verbose", "Say more: the colour space chosen and why, the config, the model").short('v');

    /// convert, expand, asset.
    BATCH_UPDATE: Flag::long("update", "update", "Skip inputs whose output is newer than the input and was made with the same settings").short('u');

    /// convert, expand, asset.
    BATCH_JSON: Flag::long("json", "json", "Print one JSON object per input on standard output, every key on every record (null where \
        it does not apply): input, output, status (ok, skipped, failed), skip_reason, error, \
        seconds, pixels, width, height, levels, bands, colorspace, colorspace_rule, subimage, \
        channels, role, bounded, non_finite, above_one, saturated, warnings; status `clipped` is a \
        conversion with pixels above 1 in reflectance. See docs/json.md");

    /// convert, expand, asset.
    BATCH_PROGRESS: Flag::long("progress", "progress", "Progress on standard error: `auto` shows a live line on a terminal (file i of n, the \
        batch's ETA) and a plain line every few seconds when standard error is a file; `always` \
        also into a pipe; `never` shows none").value("WHEN").default("auto");

    /// convert, expand, asset.
    BATCH_QUIET: Flag::long("quiet", "quiet", "Print nothing but errors (no progress, no summary)").short('q');

    /// eval.
    EVAL_SPECTRA: Flag::long("spectra", "spectra", "Measured spectra (CSV, as for train). Repeat for several files").value("CSV").required();

    /// eval.
    EVAL_METHOD: Flag::long("method", "method", "Uplift method: otsu2018 (clustered PCA), pca (one cluster), smits1999, meng2015, \
        meng2015-bounded (values kept in [0, 1] where possible) or jakob2019").value("NAME").default("otsu2018");

    /// eval.
    EVAL_MODEL: Flag::long("model", "model", "")
        .help_made(eval_model_help)
        .value("NAME|MODEL")
        .conflicts(&["train"]);

    /// eval.
    EVAL_TRAIN: Flag::long("train", "train", "Train the clustered model here on these spectra (CSV) instead of reading one").value("CSV");

    /// eval.
    EVAL_CLUSTERS: Flag::long("clusters", "clusters", "Clusters of the model trained with --train (pca: always 1)").value("K").default("8");

    /// eval.
    EVAL_MIN_CLUSTER_SIZE: Flag::long("min_cluster_size", "min-cluster-size", "Smallest cluster of the model trained with --train").value("N").made(|| vec![TrainOptions::default().min_cluster_size.to_string()]);

    /// eval.
    EVAL_BY_SET: Flag::long("by_set", "by-set", "Score each --spectra file held out of the training (leave one set out); see above");

    /// eval.
    EVAL_FOLDS: Flag::long("folds", "folds", "With --by-set: hold out K folds of each file in the recipe, training on the others' \
        spectra and the file's other folds").value("K").parser(|| value_parser!(u32).range(2..).into()).requires("by_set");

    /// eval.
    EVAL_AGAINST: Flag::long("against", "against", "With --by-set: also score this model's recorded recipe (a built-in name or a model file) \
        on the same files held out the same way, and show each file's Δe against it: what a model \
        trained on a studio's own sets gains on them and costs elsewhere").value("NAME|MODEL").requires("by_set");

    /// eval.
    EVAL_BOUNDED: Flag::long("bounded", "bounded", "Evaluate the method bounded, as `convert` writes it by default: spectra kept in [0, 1] \
        with their XYZ (reported as METHOD-bounded). Without it, the method as named");

    /// eval.
    EVAL_JSON: Flag::long("json", "json", "Print one JSON object: method, model, count, delta_e.{mean,median,max}, \
        colour_shift[].{illuminant,mean,p95,max}, roundtrip_max, roundtrip_de2000_max, \
        in_unit_range (with --by-set: sets[], mean_of_sets, worst, worst_set, colour_shift[])");

    /// eval.
    EVAL_PER_SPECTRUM: Flag::long("per_spectrum", "per-spectrum", "Also list every spectrum's error (with --json, under \"spectra\")");

    /// expand.
    EXPAND_PATHS: Flag::place("paths", "INPUT… [OUTPUT]", "Compact textures (`specconvLayout` = \"compact 2\"), then the output file when expanding \
        one; `-` reads input paths from standard input, one per line").required();

    /// expand.
    EXPAND_OUTPUT: Flag::long("output", "output", "Write every output into this directory, as STEM_spectral.exr").short('o').value("DIR").conflicts(&["output_template"]);

    /// expand.
    EXPAND_OUTPUT_TEMPLATE: Flag::long("output_template", "output-template", "Output path for each input, as `convert --output-template` names them ({dir}, {stem}, \
        {name}, {ext})").value("TEMPLATE");

    /// farm submit.
    FARM_SUBMIT_TASKS: Flag::long("tasks", "tasks", "Number of array tasks (shards)").value("N").parser(|| value_parser!(u32).range(1..).into());

    /// farm submit.
    FARM_SUBMIT_MAX_RUNNING: Flag::long("max_running", "max-running", "At most K tasks at once (`--array=0-(N-1)%K`)").value("K").parser(|| value_parser!(u32).range(1..).into());

    /// farm submit.
    FARM_SUBMIT_JOB_DIR: Flag::long("job_dir", "job-dir", "Job directory, on a file system the nodes share (default: a new specconv-farm-TIME folder \
        in the -o directory)").value("JOBDIR");

    /// farm submit.
    FARM_SUBMIT_PARTITION: Flag::long("partition", "partition", "Slurm partition").value("P");

    /// farm submit.
    FARM_SUBMIT_TIME: Flag::long("time", "time", "Time limit per task, as sbatch reads it (`30`, `2:00:00`, `1-0`)").value("T");

    /// farm submit.
    FARM_SUBMIT_CPUS_PER_TASK: Flag::long("cpus_per_task", "cpus-per-task", "CPUs per task; each task converts with that many threads").value("C").default("1").parser(|| value_parser!(u32).range(1..).into());

    /// farm submit.
    FARM_SUBMIT_MEM: Flag::long("mem", "mem", "Memory per task (`4G`, `800M`; default: the measured peak for the largest input, plus \
        half)").value("M");

    /// farm submit, farm retry.
    FARM_WAIT: Flag::long("wait", "wait", "Return when the array ends; exit 0 only if every file converted");

    /// farm submit.
    FARM_SUBMIT_DRY_RUN: Flag::long("dry_run", "dry-run", "Print the plan, the sbatch command and the script; write and submit nothing");

    /// farm status, farm collect, farm retry.
    FARM_JOB_DIR: Flag::place("job_dir", "JOBDIR", "The job directory `submit` printed");

    /// farm status, farm collect.
    FARM_JSON: Flag::long("json", "json", "One JSON object on standard output");

    /// farm retry.
    FARM_RETRY_TASKS: Flag::long("tasks", "tasks", "Number of array tasks (default: as many as the last submission, at most one per file)").value("N").parser(|| value_parser!(u32).range(1..).into());

    /// farm task.
    FARM_TASK_JOB_DIR: Flag::place("job_dir", "JOBDIR", "The job directory");

    /// farm task.
    FARM_TASK_ROUND: Flag::long("round", "round", "The round (0: the submission, then one per retry)").value("R");

    /// farm task.
    FARM_TASK_TASK: Flag::long("task", "task", "The array task ($SLURM_ARRAY_TASK_ID)").value("T");

    /// info.
    INFO_FILES: Flag::place("files", "FILES", "Image files, in any format OpenImageIO reads (EXR, TIFF/.tx, PNG, JPEG, HDR, ...). A file \
        that cannot be read is reported and the others are still shown (exit status 1)").required();

    /// info.
    INFO_COLORSPACE: Flag::long("colorspace", "colorspace", "Colour space to read the file in, overriding its declaration").value("NAME").aliases(&["iscolorspace"]);

    /// info.
    INFO_JSON: Flag::long("json", "json", "Print one JSON object per file, one per line, instead of text (docs/json.md)");

    /// models.
    MODELS_NAMES: Flag::place("models", "NAME|MODEL", "Also describe these models: built-in names or model files from `specconv train`");

    /// models.
    MODELS_JSON: Flag::long("json", "json", "Print one JSON object: in_force {model, origin, commercial}, models[] {name, builtin, \
        default, summary, commercial, clusters, sets[] {source, count, weight, licence, \
        commercial, attribution}, notices[]}, notices[] {title, text}");

    /// preview.
    PREVIEW_OUTPUT: Flag::long("output", "output", "The picture to write (.png)").short('o').value("OUT.png");

    /// preview.
    PREVIEW_ILLUMINANT: Flag::long("illuminant", "illuminant", "The light: D65, E, A, D50, FL2, FL11 or blackbody:KELVIN. Default: the file's illuminant \
        (its specconvIlluminant attribute, else D65)").value("ILLUMINANT");

    /// preview.
    PREVIEW_BOUNCES: Flag::long("bounces", "bounces", "Interreflections K: the reflectance is met K + 1 times (0: the texture as it is)").value("K").default("0").parser(|| value_parser!(u32).range(..=i64::from(MAX_BOUNCES)).into());

    /// preview.
    PREVIEW_DIFF_RGB: Flag::long("diff_rgb", "diff-rgb", "Write the CIEDE2000 heat map against plain RGB multiplication instead");

    /// preview.
    PREVIEW_JSON: Flag::long("json", "json", "Print a JSON summary (sizes, light, and ΔE max and mean with --diff-rgb) on stdout");

    /// report.
    REPORT_SPECTRA: Flag::long("spectra", "spectra", "Measured spectra to evaluate on (CSV). Repeat for several files").value("CSV").required();

    /// report.
    REPORT_TRAIN: Flag::long("train", "train", "Spectra to train the clustered models on (default: --spectra)").value("CSV").conflicts(&["holdout", "by_set"]);

    /// report.
    REPORT_BY_SET: Flag::long("by_set", "by-set", "Leave one set out: each --spectra file scored by the models trained on the others").conflicts(&["holdout"]);

    /// report.
    REPORT_HOLDOUT: Flag::long("holdout", "holdout", "K-fold cross-validation of the clustered models on --spectra (K ≥ 2)").value("K").parser(|| value_parser!(u32).range(2..).into());

    /// report.
    REPORT_CLUSTERS: Flag::long("clusters", "clusters", "Cluster counts of the otsu2018 rows (1 is the pca row)").value("K,…").default("1,2,4,8,16,32").split(',');

    /// report.
    REPORT_STEPS: Flag::long("steps", "steps", "Band widths in nm of the extra otsu2018 rows (8 clusters, same range)").value("NM,…").default("5,1").split(',');

    /// report.
    REPORT_MIN_CLUSTER_SIZE: Flag::long("min_cluster_size", "min-cluster-size", "Smallest cluster of the trained models (the paper's Table 1 used 4)").value("N").made(|| vec![TrainOptions::default().min_cluster_size.to_string()]);

    /// report.
    REPORT_COLOURS: Flag::long("colours", "colours", "Colours uplifted to measure the cost of each method").value("N").made(|| vec![(1_usize << 20).to_string()]);

    /// report.
    REPORT_THREADS: Flag::long("threads", "threads", "Threads of the \"all threads\" measurement (default: one per core)").short('j').value("N");

    /// report.
    REPORT_JSON: Flag::long("json", "json", "Print the table as JSON").conflicts(&["csv"]);

    /// report.
    REPORT_CSV: Flag::long("csv", "csv", "Print the table as CSV");

    /// report.
    REPORT_PLOT: Flag::long("plot", "plot", "Also draw accuracy (Δe mean) against time per colour into FILE: SVG or PNG, by the \
        extension (.svg, .png). Text needs a TrueType font: DejaVu Sans (Debian package \
        fonts-dejavu-core) or the file named by $SPECCONV_FONT").value("FILE.svg|FILE.png");

    /// simulate.
    SIMULATE_SCENE: Flag::long("scene", "scene", "The scene (TOML); relative paths in it are relative to its directory").value("SCENE.toml");

    /// simulate.
    SIMULATE_PER_PATCH: Flag::long("per_patch", "per-patch", "Report every patch, not only the means (the default for scenes of up to 16 patches)");

    /// simulate.
    SIMULATE_PATCH: Flag::long("patch", "patch", "Report (and draw) only this patch; repeat for several. Means stay over all patches").value("NAME");

    /// simulate.
    SIMULATE_IMAGE: Flag::long("image", "image", "Also draw the report as a PNG: one block per patch (at most 16: choose with --patch), one \
        row per rendering (the measured reference, each method, `rgb` multiplication), one column \
        per bounce count; each swatch in display sRGB (the white scene's Y as 1) with its \
        CIEDE2000 from the measured reference under it (from `rgb` where the scene has no measured \
        spectra). Text needs DejaVu Sans (fonts-dejavu-core) or $SPECCONV_FONT").value("OUT.png");

    /// simulate.
    SIMULATE_FORCE: Flag::long("force", "force", "Replace an existing --image file").requires("image");

    /// simulate.
    SIMULATE_METHODS: Flag::long("methods", "method", "Uplift method to compare, instead of the scene's `methods`; repeat for several: otsu2018, \
        pca, smits1999, meng2015, meng2015-bounded or jakob2019. Each is built as `convert` builds \
        it, with the options below and their defaults").value("NAME");

    /// to-rgb.
    TO_RGB_COLORSPACE: Flag::long("colorspace", "colorspace", "Colour space of the output; default: the config's scene_linear role").value("NAME");

    /// to-rgb.
    TO_RGB_ILLUMINANT: Flag::long("illuminant", "illuminant", "Light the reflectances under this illuminant instead of the file's (reflectance files \
        only: emission is its own light)").value("ILLUMINANT");

    /// train.
    TRAIN_SPECTRA: Flag::long("spectra", "spectra", "Measured spectra: CSV with a wavelength column, then one column per named sample. Repeat \
        to train on several files (none with --with: the model's own data alone, which gives the \
        model back bit for bit)").value("CSV").required_unless("with");

    /// train.
    TRAIN_CLUSTERS: Flag::long("clusters", "clusters", "Number of clusters (leaves of the tree) [default: 8, or the --with model's]").value("K");

    /// train.
    TRAIN_MIN_CLUSTER_SIZE: Flag::long("min_cluster_size", "min-cluster-size", "Smallest number of spectra in a cluster. Small clusters fit their training spectra closely \
        but generalise badly; the paper's Table 1 used 4 [default: 20, or the --with model's]").value("N").parser(|| ValueParser::new(min_cluster_size));

    /// train.
    TRAIN_MAX_CONDITION: Flag::long("max_condition", "max-condition", "Largest condition number of a cluster's 3×3 matrix M that a split may create. \
        Near-singular M turn colours the cluster was not trained on into wild spectra [default: \
        100, or the --with model's]").value("BOUND");

    /// train.
    TRAIN_WITH: Flag::long("with", "with", "Train on top of a model's own data: a built-in model (NAME) or a model file, whose \
        recorded sets (read from --with-data) join the --spectra files with their recorded weights \
        and terms, in its grid, observer and illuminant, its options the defaults of the three \
        above. The way to a model a studio owns: its swatches on top of `open`").value("NAME|MODEL").requires("with_data");

    /// train.
    TRAIN_WITH_DATA: Flag::long("with_data", "with-data", "The folder holding the --with model's sets, by the file names it records \
        (../shared/spectra for the built-in models)").value("DIR").requires("with");

    /// train.
    TRAIN_OUTPUT: Flag::long("output", "output", "Where to write the model (JSON)").short('o').value("MODEL");

    /// eval, report.
    SHIFT_UNDER: Flag::long("shift_under", "shift-under", "Measure the colour shift a viewer sees under these illuminants: CIEDE2000 between each \
        measured spectrum and its uplift, lit by the illuminant (CIE A, D65, D50, FL2, FL11, E or \
        blackbody:KELVIN), through the model's observer, white = the perfect reflector under it").value("ILLUMINANT,…").made(|| SHIFT_ILLUMINANTS.iter().map(ToString::to_string).collect()).split(',');

    /// eval.
    EVAL_OBSERVER: Flag::long("observer", "observer", "Colour-matching functions for baselines and in-place training: cie1931, cie1964 or \
        wyman2013 (default: the model's, cie1931 for the built-in one)").value("OBSERVER");

    /// eval.
    EVAL_ILLUMINANT: Flag::long("illuminant", "illuminant", "Illuminant for baselines and in-place training: D65, E, A, D50, FL2, FL11 or \
        blackbody:KELVIN (default: the model's, D65 for the built-in one)").value("ILLUMINANT");

    /// eval.
    EVAL_BANDS: Flag::long("bands", "bands", "Wavelength grid START:END:STEP in nm (default: the model's, 380:730:10 for the built-in)").value("START:END:STEP");

    /// eval, report.
    JAKOB_RESOLUTION: Flag::long("resolution", "jakob-resolution", "Resolution of the jakob2019 coefficient table (cells per axis; the paper's 64)").value("N").made(|| vec![jakob::DEFAULT_RESOLUTION.to_string()]);

    /// train, report.
    TRAINING_OBSERVER: Flag::long("observer", "observer", "Colour-matching functions: cie1931, cie1964 or wyman2013 (the paper's)").value("OBSERVER").default("cie1931");

    /// train, report.
    TRAINING_ILLUMINANT: Flag::long("illuminant", "illuminant", "Illuminant under which reflectances become colours: D65, E, A, D50, FL2, FL11 or \
        blackbody:KELVIN. E reproduces the paper's setting").value("ILLUMINANT").default("D65");

    /// train, report.
    TRAINING_BANDS: Flag::long("bands", "bands", "Wavelength grid START:END:STEP in nm, both ends included").value("START:END:STEP").default("380:730:10");

    /// train, eval, report.
    WEIGHTS: Flag::long("weights", "weights", "Weight of each --spectra file's spectra, in their order (default 1 each): a file of weight \
        2 counts as if each of its spectra were there twice. Recorded in the model").value("W,…").split(',');

    /// train, eval, report.
    BALANCE: Flag::long("balance", "balance", "How far set sizes are evened out, 0 to 1: 0 lets every spectrum count the same (the \
        largest file decides most), 1 lets every file count the same in total, 0.5 between \
        (weights ∝ size^−balance, times --weights, averaging 1)").value("B").default("0");

    /// train, eval, report.
    LICENCES: Flag::long("licences", "licence", "The terms of use of each --spectra file's data, in their order, recorded in the model \
        (default: the licence ../shared/spectra/README.md states for the file name, else \
        \"unknown\")").value("TEXT");

    /// train, eval, report.
    COMMERCIAL: Flag::long("commercial", "commercial", "Whether each --spectra file's data may be used commercially (yes, no, unstated), in their \
        order, recorded in the model: a model may be used commercially only when all its sets may. \
        Default: what ../shared/spectra/README.md states for the file name, else unstated; for \
        your own measurements pass yes").value("yes|no|unstated");

    /// train, eval, report.
    HOLD_ENDS: Flag::long("hold_ends", "hold-ends", "Hold a --spectra file that stops short of the grid at its first and last measured values \
        (CIE 015's practice for missing data; recorded in the model) instead of refusing it: for a \
        set measured on 400–700 nm, say");

    /// completions.
    COMPLETIONS_SHELL: Flag::place("shell", "SHELL", "The shell to complete for");

    /// preview.
    PREVIEW_INPUT: Flag::place("input", "INPUT", "A spectral OpenEXR of reflectances (Fichet et al. 2021 layout), e.g. from convert; or of \
        emission, with no bounces");

    /// to-rgb.
    TO_RGB_INPUT: Flag::place("input", "INPUT", "A spectral OpenEXR (Fichet et al. 2021 layout), e.g. written by specconv");

    /// to-rgb.
    TO_RGB_OUTPUT: Flag::place("output", "OUTPUT", "The colour image to write (.exr)");
}
