//! Every command's own flags, each defined once: the commands list which they take
//! ([`crate::args!`]); the conversion's options are the library's ([`crate::OptionArgs`]).
//! An entry is named for the command that takes it (`EVAL_…`), or for what the commands that
//! share it share (`BATCH_…`, `WEIGHTS`). A long name several entries share means something
//! else in each command, and a test of the command line says what.

use crate::Flag;
use clap::builder::ValueParser;
use clap::value_parser;
use specconv_colour::{Grid, Illuminant, Observer};
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
    ASSET_STAGE: Flag::place("stage", "STAGE", "The USD stage, or a MaterialX document");

    ASSET_OUTPUT: Flag::long(
        "output",
        "The output directory (made if missing); nothing is written outside it",
    )
    .short('o')
    .value("DIR")
    .required();

    ASSET_DRY_RUN: Flag::long(
        "dry-run",
        "Print each texture's decision (and its output) without converting or writing anything",
    );

    ASSET_VERBOSE: Flag::long("verbose", "Say more: each texture's decision before converting")
    .short('v');

    JSON_INSTEAD_OF_TEXT: Flag::long("json", "Print one JSON object instead of text");

    CONVERT_PATHS: Flag::place(
        "paths",
        "INPUT… [OUTPUT]",
        "Input textures, then the output file when converting one; `-` reads input paths from \
         standard input, one per line. A UDIM pattern (`wood.<UDIM>.png`, `<udim>` or `%(UDIM)d` \
         in the file name) stands for the tiles that exist, in tile order; converting one pattern, \
         name the output with the token too (`wood_spectral.<UDIM>.exr`)",
    )
    .required();

    CONVERT_OUTPUT: Flag::long(
        "output",
        "Write every output into this directory, as STEM_spectral.exr (a data texture written \
         through by --data copy as STEM_data.exr)",
    )
    .short('o')
    .value("DIR")
    .conflicts(&["output-template"]);

    CONVERT_OUTPUT_TEMPLATE: Flag::long(
        "output-template",
        "Output path for each input; {dir}, {stem}, {name} and {ext} are the input's directory, \
         name without extension, file name and extension, {udim} its UDIM tile number (1001…), \
         {tile} the same tile as u1_v1 ('{dir}/{stem}_{ext}_spectral.exr' keeps brick.png and \
         brick.tx apart) and {role} 'spectral', or 'data' for a data texture written through \
         (without {role} both are one name). With {udim} or {tile}, {stem} leaves the tile number \
         out: '{dir}/{stem}_spectral.{udim}.exr' makes wood_spectral.1001.exr of wood.1001.png. \
         Any other {field} is refused before anything is written",
    )
    .value("TEMPLATE");

    CONVERT_SHARD: Flag::long(
        "shard",
        "Convert only shard I of N (`I/N`, I from 0), or `auto/N` with I from \
         $SLURM_ARRAY_TASK_ID: inputs split by pixel count, the same plan on every run and as \
         `farm submit`, so N runs given the same inputs convert each exactly once",
    )
    .value("I/N");

    CONVERT_VERBOSE: Flag::long(
        "verbose",
        "Say more: the colour space chosen and why, the config, the model",
    )
    .short('v');

    BATCH_UPDATE: Flag::long(
        "update",
        "Skip inputs whose output is newer than the input and was made with the same settings",
    )
    .short('u');

    BATCH_JSON: Flag::long(
        "json",
        "Print one JSON object per input on standard output, every key on every record (null where \
         it does not apply): input, output, status (ok, skipped, failed), skip_reason, error, \
         seconds, pixels, width, height, levels, bands, colorspace, colorspace_rule, subimage, \
         channels, role, bounded, non_finite, above_one, saturated, warnings; status `clipped` is \
         a conversion with pixels above 1 in reflectance. See docs/json.md",
    );

    BATCH_PROGRESS: Flag::long(
        "progress",
        "Progress on standard error: `auto` shows a live line on a terminal (file i of n, the \
         batch's ETA) and a plain line every few seconds when standard error is a file; `always` \
         also into a pipe; `never` shows none",
    )
    .value("WHEN")
    .default("auto");

    BATCH_QUIET: Flag::long("quiet", "Print nothing but errors (no progress, no summary)")
    .short('q');

    EVAL_SPECTRA: Flag::long(
        "spectra",
        "Measured spectra (CSV, as for train). Repeat for several files",
    )
    .value("CSV")
    .required();

    EVAL_METHOD: Flag::long(
        "method",
        "Uplift method: otsu2018 (clustered PCA), pca (one cluster), smits1999, meng2015, \
         meng2015-bounded (values kept in [0, 1] where possible) or jakob2019",
    )
    .value("NAME")
    .default("otsu2018");

    EVAL_MODEL: Flag::long("model", "")
    .help_made(eval_model_help)
    .value("NAME|MODEL")
    .conflicts(&["train"]);

    EVAL_TRAIN: Flag::long(
        "train",
        "Train the clustered model here on these spectra (CSV) instead of reading one",
    )
    .value("CSV");

    EVAL_CLUSTERS: Flag::long(
        "clusters",
        "Clusters of the model trained with --train (pca: always 1)",
    )
    .value("K")
    .made(|| vec![TrainOptions::default().clusters.to_string()]);

    EVAL_MIN_CLUSTER_SIZE: Flag::long(
        "min-cluster-size",
        "Smallest cluster of the model trained with --train",
    )
    .value("N")
    .made(|| vec![TrainOptions::default().min_cluster_size.to_string()]);

    EVAL_BY_SET: Flag::long(
        "by-set",
        "Score each --spectra file held out of the training (leave one set out); see above",
    );

    EVAL_FOLDS: Flag::long(
        "folds",
        "With --by-set: hold out K folds of each file in the recipe, training on the others' \
         spectra and the file's other folds",
    )
    .value("K")
    .parser(|| value_parser!(u32).range(2..).into())
    .requires("by-set");

    EVAL_AGAINST: Flag::long(
        "against",
        "With --by-set: also score this model's recorded recipe (a built-in name or a model file) \
         on the same files held out the same way, and show each file's Δe against it: what a model \
         trained on a studio's own sets gains on them and costs elsewhere",
    )
    .value("NAME|MODEL")
    .requires("by-set");

    EVAL_BOUNDED: Flag::long(
        "bounded",
        "Evaluate the method bounded, as `convert` writes it by default: spectra kept in [0, 1] \
         with their XYZ (reported as METHOD-bounded). Without it, the method as named",
    );

    EVAL_JSON: Flag::long(
        "json",
        "Print one JSON object: method, model, count, delta_e.{mean,median,max}, \
         colour_shift[].{illuminant,mean,p95,max}, roundtrip_max, roundtrip_de2000_max, \
         in_unit_range (with --by-set: sets[], mean_of_sets, worst, worst_set, colour_shift[])",
    );

    EVAL_PER_SPECTRUM: Flag::long(
        "per-spectrum",
        "Also list every spectrum's error (with --json, under \"spectra\")",
    );

    EXPAND_PATHS: Flag::place(
        "paths",
        "INPUT… [OUTPUT]",
        "Compact textures (`specconvLayout` = \"compact 2\"), then the output file when expanding \
         one; `-` reads input paths from standard input, one per line",
    )
    .required();

    EXPAND_OUTPUT: Flag::long(
        "output",
        "Write every output into this directory, as STEM_spectral.exr",
    )
    .short('o')
    .value("DIR")
    .conflicts(&["output-template"]);

    EXPAND_OUTPUT_TEMPLATE: Flag::long(
        "output-template",
        "Output path for each input, as `convert --output-template` names them ({dir}, {stem}, \
         {name}, {ext})",
    )
    .value("TEMPLATE");

    FARM_SUBMIT_TASKS: Flag::long("tasks", "Number of array tasks (shards)")
    .value("N")
    .parser(|| value_parser!(u32).range(1..).into());

    FARM_SUBMIT_MAX_RUNNING: Flag::long(
        "max-running",
        "At most K tasks at once (`--array=0-(N-1)%K`)",
    )
    .value("K")
    .parser(|| value_parser!(u32).range(1..).into());

    FARM_SUBMIT_JOB_DIR: Flag::long(
        "job-dir",
        "Job directory, on a file system the nodes share (default: a new specconv-farm-TIME folder \
         in the -o directory)",
    )
    .value("JOBDIR");

    FARM_SUBMIT_PARTITION: Flag::long("partition", "Slurm partition").value("P");

    FARM_SUBMIT_TIME: Flag::long(
        "time",
        "Time limit per task, as sbatch reads it (`30`, `2:00:00`, `1-0`)",
    )
    .value("T");

    FARM_SUBMIT_CPUS_PER_TASK: Flag::long(
        "cpus-per-task",
        "CPUs per task; each task converts with that many threads",
    )
    .value("C")
    .default("1")
    .parser(|| value_parser!(u32).range(1..).into());

    FARM_SUBMIT_MEM: Flag::long(
        "mem",
        "Memory per task (`4G`, `800M`; default: the measured peak for the largest input, plus \
         half)",
    )
    .value("M");

    FARM_WAIT: Flag::long(
        "wait",
        "Return when the array ends; exit 0 only if every file converted",
    );

    FARM_SUBMIT_DRY_RUN: Flag::long(
        "dry-run",
        "Print the plan, the sbatch command and the script; write and submit nothing",
    );

    FARM_JOB_DIR: Flag::place("job_dir", "JOBDIR", "The job directory `submit` printed");

    FARM_JSON: Flag::long("json", "One JSON object on standard output");

    FARM_RETRY_TASKS: Flag::long(
        "tasks",
        "Number of array tasks (default: as many as the last submission, at most one per file)",
    )
    .value("N")
    .parser(|| value_parser!(u32).range(1..).into());

    FARM_TASK_JOB_DIR: Flag::place("job_dir", "JOBDIR", "The job directory");

    FARM_TASK_ROUND: Flag::long("round", "The round (0: the submission, then one per retry)")
    .value("R");

    FARM_TASK_TASK: Flag::long("task", "The array task ($SLURM_ARRAY_TASK_ID)").value("T");

    INFO_FILES: Flag::place(
        "files",
        "FILES",
        "Image files, in any format OpenImageIO reads (EXR, TIFF/.tx, PNG, JPEG, HDR, ...). A file \
         that cannot be read is reported and the others are still shown (exit status 1)",
    )
    .required();

    INFO_COLORSPACE: Flag::long(
        "colorspace",
        "Colour space to read the file in, overriding its declaration",
    )
    .value("NAME")
    .aliases(&["iscolorspace"]);

    INFO_JSON: Flag::long(
        "json",
        "Print one JSON object per file, one per line, instead of text (docs/json.md)",
    );

    MODELS_NAMES: Flag::place(
        "models",
        "NAME|MODEL",
        "Also describe these models: built-in names or model files from `specconv train`",
    );

    MODELS_JSON: Flag::long(
        "json",
        "Print one JSON object: in_force {model, origin, commercial}, models[] {name, builtin, \
         default, summary, commercial, clusters, sets[] {source, count, weight, licence, \
         commercial, attribution}, notices[]}, notices[] {title, text}",
    );

    PREVIEW_OUTPUT: Flag::long("output", "The picture to write (.png)").short('o').value("OUT.png");

    PREVIEW_ILLUMINANT: Flag::long(
        "illuminant",
        "The light: D65, E, A, D50, FL2, FL11 or blackbody:KELVIN. Default: the file's illuminant \
         (its specconvIlluminant attribute, else D65)",
    )
    .value("ILLUMINANT");

    PREVIEW_BOUNCES: Flag::long(
        "bounces",
        "Interreflections K: the reflectance is met K + 1 times (0: the texture as it is)",
    )
    .value("K")
    .default("0")
    .parser(|| value_parser!(u32).range(..=i64::from(MAX_BOUNCES)).into());

    PREVIEW_DIFF_RGB: Flag::long(
        "diff-rgb",
        "Write the CIEDE2000 heat map against plain RGB multiplication instead",
    );

    PREVIEW_JSON: Flag::long(
        "json",
        "Print a JSON summary (sizes, light, and ΔE max and mean with --diff-rgb) on stdout",
    );

    REPORT_SPECTRA: Flag::long(
        "spectra",
        "Measured spectra to evaluate on (CSV). Repeat for several files",
    )
    .value("CSV")
    .required();

    REPORT_TRAIN: Flag::long(
        "train",
        "Spectra to train the clustered models on (default: --spectra)",
    )
    .value("CSV")
    .conflicts(&["holdout", "by-set"]);

    REPORT_BY_SET: Flag::long(
        "by-set",
        "Leave one set out: each --spectra file scored by the models trained on the others",
    )
    .conflicts(&["holdout"]);

    REPORT_HOLDOUT: Flag::long(
        "holdout",
        "K-fold cross-validation of the clustered models on --spectra (K ≥ 2)",
    )
    .value("K")
    .parser(|| value_parser!(u32).range(2..).into());

    REPORT_CLUSTERS: Flag::long(
        "clusters",
        "Cluster counts of the otsu2018 rows (1 is the pca row)",
    )
    .value("K,…")
    .default("1,2,4,8,16,32")
    .split(',');

    REPORT_STEPS: Flag::long(
        "steps",
        "Band widths in nm of the extra otsu2018 rows (8 clusters, same range)",
    )
    .value("NM,…")
    .default("5,1")
    .split(',');

    REPORT_MIN_CLUSTER_SIZE: Flag::long(
        "min-cluster-size",
        "Smallest cluster of the trained models (the paper's Table 1 used 4)",
    )
    .value("N")
    .made(|| vec![TrainOptions::default().min_cluster_size.to_string()]);

    REPORT_COLOURS: Flag::long("colours", "Colours uplifted to measure the cost of each method")
    .value("N")
    .made(|| vec![(1_usize << 20).to_string()]);

    REPORT_THREADS: Flag::long(
        "threads",
        "Threads of the \"all threads\" measurement (default: one per core)",
    )
    .short('j')
    .value("N");

    REPORT_JSON: Flag::long("json", "Print the table as JSON").conflicts(&["csv"]);

    REPORT_CSV: Flag::long("csv", "Print the table as CSV");

    REPORT_PLOT: Flag::long(
        "plot",
        "Also draw accuracy (Δe mean) against time per colour into FILE: SVG or PNG, by the \
         extension (.svg, .png). Text needs a TrueType font: DejaVu Sans (Debian package \
         fonts-dejavu-core) or the file named by $SPECCONV_FONT",
    )
    .value("FILE.svg|FILE.png");

    SIMULATE_SCENE: Flag::long(
        "scene",
        "The scene (TOML); relative paths in it are relative to its directory",
    )
    .value("SCENE.toml");

    SIMULATE_PER_PATCH: Flag::long(
        "per-patch",
        "Report every patch, not only the means (the default for scenes of up to 16 patches)",
    );

    SIMULATE_PATCH: Flag::long(
        "patch",
        "Report (and draw) only this patch; repeat for several. Means stay over all patches",
    )
    .value("NAME");

    SIMULATE_IMAGE: Flag::long(
        "image",
        "Also draw the report as a PNG: one block per patch (at most 16: choose with --patch), one \
         row per rendering (the measured reference, each method, `rgb` multiplication), one column \
         per bounce count; each swatch in display sRGB (the white scene's Y as 1) with its \
         CIEDE2000 from the measured reference under it (from `rgb` where the scene has no \
         measured spectra). Text needs DejaVu Sans (fonts-dejavu-core) or $SPECCONV_FONT",
    )
    .value("OUT.png");

    SIMULATE_FORCE: Flag::long("force", "Replace an existing --image file").requires("image");

    SIMULATE_METHODS: Flag::long(
        "method",
        "Uplift method to compare, instead of the scene's `methods`; repeat for several: otsu2018, \
         pca, smits1999, meng2015, meng2015-bounded or jakob2019. Each is built as `convert` \
         builds it, with the options below and their defaults",
    )
    .value("NAME");

    TO_RGB_COLORSPACE: Flag::long(
        "colorspace",
        "Colour space of the output; default: the config's scene_linear role",
    )
    .value("NAME");

    TO_RGB_ILLUMINANT: Flag::long(
        "illuminant",
        "Light the reflectances under this illuminant instead of the file's (reflectance files \
         only: emission is its own light)",
    )
    .value("ILLUMINANT");

    TRAIN_SPECTRA: Flag::long(
        "spectra",
        "Measured spectra: CSV with a wavelength column, then one column per named sample. Repeat \
         to train on several files (none with --with: the model's own data alone, which gives the \
         model back bit for bit)",
    )
    .value("CSV")
    .required_unless("with");

    TRAIN_CLUSTERS: Flag::long("clusters", "")
        .help_made(|| {
            format!(
                "Number of clusters (leaves of the tree) [default: {}, or the --with model's]",
                TrainOptions::default().clusters
            )
        })
        .value("K");

    TRAIN_MIN_CLUSTER_SIZE: Flag::long("min-cluster-size", "")
        .help_made(|| {
            format!(
                "Smallest number of spectra in a cluster. Small clusters fit their training \
                 spectra closely but generalise badly; the paper's Table 1 used 4 [default: {}, \
                 or the --with model's]",
                TrainOptions::default().min_cluster_size
            )
        })
        .value("N")
    .parser(|| ValueParser::new(min_cluster_size));

    TRAIN_MAX_CONDITION: Flag::long("max-condition", "")
        .help_made(|| {
            format!(
                "Largest condition number of a cluster's 3×3 matrix M that a split may create. \
                 Near-singular M turn colours the cluster was not trained on into wild spectra \
                 [default: {}, or the --with model's]",
                TrainOptions::default().max_condition
            )
        })
        .value("BOUND");

    TRAIN_WITH: Flag::long(
        "with",
        "Train on top of a model's own data: a built-in model (NAME) or a model file, whose \
         recorded sets (read from --with-data) join the --spectra files with their recorded \
         weights and terms, in its grid, observer and illuminant, its options the defaults of the \
         three above. The way to a model a studio owns: its swatches on top of `open`",
    )
    .value("NAME|MODEL")
    .requires("with-data");

    TRAIN_WITH_DATA: Flag::long(
        "with-data",
        "The folder holding the --with model's sets, by the file names it records \
         (../shared/spectra for the built-in models)",
    )
    .value("DIR")
    .requires("with");

    TRAIN_OUTPUT: Flag::long("output", "Where to write the model (JSON)").short('o').value("MODEL");

    SHIFT_UNDER: Flag::long(
        "shift-under",
        "Measure the colour shift a viewer sees under these illuminants: CIEDE2000 between each \
         measured spectrum and its uplift, lit by the illuminant (CIE A, D65, D50, FL2, FL11, E or \
         blackbody:KELVIN), through the model's observer, white = the perfect reflector under it",
    )
    .value("ILLUMINANT,…")
    .made(|| SHIFT_ILLUMINANTS.iter().map(ToString::to_string).collect())
    .split(',');

    EVAL_OBSERVER: Flag::long(
        "observer",
        "Colour-matching functions for baselines and in-place training: cie1931, cie1964 or \
         wyman2013 (default: the model's, cie1931 for the built-in one)",
    )
    .value("OBSERVER");

    EVAL_ILLUMINANT: Flag::long(
        "illuminant",
        "Illuminant for baselines and in-place training: D65, E, A, D50, FL2, FL11 or \
         blackbody:KELVIN (default: the model's, D65 for the built-in one)",
    )
    .value("ILLUMINANT");

    EVAL_BANDS: Flag::long(
        "bands",
        "Wavelength grid START:END:STEP in nm (default: the model's, 380:730:10 for the built-in)",
    )
    .value("START:END:STEP");

    JAKOB_RESOLUTION: Flag::long(
        "jakob-resolution",
        "Resolution of the jakob2019 coefficient table (cells per axis; the paper's 64)",
    )
    .value("N")
    .made(|| vec![jakob::DEFAULT_RESOLUTION.to_string()]);

    TRAINING_OBSERVER: Flag::long(
        "observer",
        "Colour-matching functions: cie1931, cie1964 or wyman2013 (the paper's)",
    )
    .value("OBSERVER")
    .made(|| vec![Observer::Cie1931.name().to_string()]);

    TRAINING_ILLUMINANT: Flag::long(
        "illuminant",
        "Illuminant under which reflectances become colours: D65, E, A, D50, FL2, FL11 or \
         blackbody:KELVIN. E reproduces the paper's setting",
    )
    .value("ILLUMINANT")
    .made(|| vec![Illuminant::D65.to_string()]);

    TRAINING_BANDS: Flag::long("bands", "Wavelength grid START:END:STEP in nm, both ends included")
    .value("START:END:STEP")
    .made(|| vec![Grid::PAPER.to_string()]);

    WEIGHTS: Flag::long(
        "weights",
        "Weight of each --spectra file's spectra, in their order (default 1 each): a file of \
         weight 2 counts as if each of its spectra were there twice. Recorded in the model",
    )
    .value("W,…")
    .split(',');

    BALANCE: Flag::long(
        "balance",
        "How far set sizes are evened out, 0 to 1: 0 lets every spectrum count the same (the \
         largest file decides most), 1 lets every file count the same in total, 0.5 between \
         (weights ∝ size^−balance, times --weights, averaging 1)",
    )
    .value("B")
    .default("0");

    LICENCES: Flag::long(
        "licence",
        "The terms of use of each --spectra file's data, in their order, recorded in the model \
         (default: the licence ../shared/spectra/README.md states for the file name, else \
         \"unknown\")",
    )
    .value("TEXT");

    COMMERCIAL: Flag::long(
        "commercial",
        "Whether each --spectra file's data may be used commercially (yes, no, unstated), in their \
         order, recorded in the model: a model may be used commercially only when all its sets \
         may. Default: what ../shared/spectra/README.md states for the file name, else unstated; \
         for your own measurements pass yes",
    )
    .value("yes|no|unstated");

    HOLD_ENDS: Flag::long(
        "hold-ends",
        "Hold a --spectra file that stops short of the grid at its first and last measured values \
         (CIE 015's practice for missing data; recorded in the model) instead of refusing it: for \
         a set measured on 400–700 nm, say",
    );

    COMPLETIONS_SHELL: Flag::place("shell", "SHELL", "The shell to complete for");

    PREVIEW_INPUT: Flag::place(
        "input",
        "INPUT",
        "A spectral OpenEXR of reflectances (Fichet et al. 2021 layout), e.g. from convert; or of \
         emission, with no bounces",
    );

    TO_RGB_INPUT: Flag::place(
        "input",
        "INPUT",
        "A spectral OpenEXR (Fichet et al. 2021 layout), e.g. written by specconv",
    );

    TO_RGB_OUTPUT: Flag::place("output", "OUTPUT", "The colour image to write (.exr)");
}
