//! The method options of the commands, turned into the one [`StackSpec`] that
//! `specconv_spectral::stack` builds: `simulate` takes [`StackArgs`] (the conversion's options, with the
//! library's help and defaults), `eval` and `report` their setting flags. The
//! Jakob 2019 tables are kept where the library keeps them ([`specconv_conversion::tables`]).

use anyhow::Result;
use specconv_colour::Colorimetry;
use specconv_convert_cmd::errors::usage;
use specconv_flags::defs;
use specconv_spectral::method::MethodName;
use specconv_spectral::stack::{Setting, Stack, StackSpec};
use specconv_spectral::Model;
use std::path::{Path, PathBuf};

/// `--blend WIDTH` of the commands that uplift with a clustered model, as the library defines it.
pub type BlendArg = specconv_flags::OptionArgs<specconv_flags::Blending>;

specconv_flags::args! {
    /// The lights colour shift is measured under (`eval`, `report`).
    #[derive(Debug, Clone)]
    pub struct ShiftArg {
        pub shift_under: Vec<specconv_colour::Illuminant> = (defs::SHIFT_UNDER),
    }
}

impl ShiftArg {
    /// Where the colour shift is measured, for evaluations in `a`'s setting.
    pub fn viewing(&self, a: &Colorimetry) -> Result<specconv_evaluation::eval::Viewing> {
        specconv_evaluation::eval::Viewing::new(a, &self.shift_under).map_err(|e| {
            usage(anyhow::anyhow!(
                "--shift-under: {e}; choose bands inside that range, or name illuminants whose tables cover the grid with --shift-under"
            ))
        })
    }
}

/// The options of the method stack that `simulate` shares with a conversion, with the
/// library's help and defaults.
pub type StackArgs = specconv_flags::OptionArgs<specconv_flags::Stacking>;

/// `method` with the stack's options, reflectances as every reader of the output integrates them.
pub fn describe(args: &StackArgs, method: MethodName) -> StackSpec {
    let o = &args.options;
    StackSpec {
        blend: o.blend,
        grid: o.bands,
        bounded: o.bounded,
        ..StackSpec::convert_default(method)
    }
}

/// Builds `d` with `model` and the cached tables.
pub fn build(d: &StackSpec, model: &Model) -> Result<Stack> {
    let tables = specconv_conversion::tables::in_dir(None, specconv_conversion::tables::print_note);
    Ok(Stack::build(d, model, &tables)?)
}

specconv_flags::args! {
    /// Colorimetry flags shared by `eval` and `report`.
    #[derive(Debug, Clone)]
    pub struct SettingArgs {
        pub observer: Option<specconv_colour::Observer> = (defs::EVAL_OBSERVER),
        pub illuminant: Option<specconv_colour::Illuminant> = (defs::EVAL_ILLUMINANT),
        pub bands: Option<specconv_colour::Grid> = (defs::EVAL_BANDS),
        pub jakob: JakobArg = flatten,
    }
}

specconv_flags::args! {
    /// `--jakob-resolution N` of the commands that measure jakob2019 (`eval`, `report`).
    #[derive(Debug, Clone, Copy)]
    pub struct JakobArg {
        pub resolution: usize = (defs::JAKOB_RESOLUTION),
    }
}

impl SettingArgs {
    /// The colorimetry: the flags, falling back to `model`'s setting.
    pub fn colorimetry(&self, model: &Model) -> Result<Colorimetry> {
        Ok(Colorimetry::new(
            self.bands.unwrap_or(model.grid),
            self.observer.unwrap_or(model.observer),
            self.illuminant.unwrap_or(model.illuminant),
        )?)
    }

    /// `method` as `eval` measures it, in this setting.
    pub fn describe(&self, method: MethodName, blend: f64, bounded: bool) -> StackSpec {
        let setting = Setting {
            grid: self.bands,
            observer: self.observer,
            illuminant: self.illuminant,
        };
        StackSpec::measured(method, blend, setting, self.jakob.resolution, bounded)
    }
}

specconv_flags::args! {
    /// The colorimetry flags of `train` and `report`, with the built-in model's setting as default.
    #[derive(Debug, Clone)]
    pub struct ColorimetryArgs {
        pub observer: specconv_colour::Observer = (defs::TRAINING_OBSERVER),
        pub illuminant: specconv_colour::Illuminant = (defs::TRAINING_ILLUMINANT),
        pub bands: specconv_colour::Grid = (defs::TRAINING_BANDS),
    }
}

impl ColorimetryArgs {
    /// The colorimetry on `grid` (another grid than --bands, for report's --steps rows).
    pub fn on(&self, grid: specconv_colour::Grid) -> Result<Colorimetry> {
        Ok(Colorimetry::new(grid, self.observer, self.illuminant)?)
    }

    /// The flags as the setting of the baselines.
    pub fn setting(&self) -> Setting {
        Setting {
            grid: Some(self.bands),
            observer: Some(self.observer),
            illuminant: Some(self.illuminant),
        }
    }
}

/// Reads spectra files into one training set on `grid`.
pub fn training_set(
    paths: &[PathBuf],
    grid: &specconv_colour::Grid,
) -> Result<specconv_spectral::TrainingSet> {
    weighted_set(paths, grid, &WeightArgs::default())
}

specconv_flags::args! {
    /// How `train` weighs its --spectra files and what it records of their terms of use.
    #[derive(Debug, Clone, Default)]
    pub struct WeightArgs {
        pub weights: Vec<f64> = (defs::WEIGHTS),
        pub balance: f64 = (defs::BALANCE),
        pub licences: Vec<String> = (defs::LICENCES),
        pub commercial: Vec<specconv_spectral::otsu2018::terms::Commercial> = (defs::COMMERCIAL),
        pub hold_ends: bool = (defs::HOLD_ENDS),
    }
}

/// The --spectra files as one training set, weighted and with their licences.
pub fn weighted_set(
    paths: &[PathBuf],
    grid: &specconv_colour::Grid,
    w: &WeightArgs,
) -> Result<specconv_spectral::TrainingSet> {
    let parts = weighted_parts(paths, grid, w)?;
    specconv_spectral::TrainingSet::union(&parts, w.balance).map_err(usage)
}

/// The --spectra files, one part each, with the weights and licences of `w` (before
/// [`WeightArgs::balance`], which [`specconv_spectral::TrainingSet::union`] applies).
pub fn weighted_parts(
    paths: &[PathBuf],
    grid: &specconv_colour::Grid,
    w: &WeightArgs,
) -> Result<Vec<specconv_spectral::Part>> {
    use specconv_spectral::otsu2018::terms::Terms;
    for (flag, count) in [
        ("--weights", w.weights.len()),
        ("--licence", w.licences.len()),
        ("--commercial", w.commercial.len()),
    ] {
        if count != 0 && count != paths.len() {
            return Err(usage(anyhow::anyhow!(
                "{count} values of {flag} for {} --spectra files: give one per file, in their order",
                paths.len()
            )));
        }
    }
    let mut parts = Vec::with_capacity(paths.len());
    for (k, path) in paths.iter().enumerate() {
        let (table, sha256) = specconv_conversion::models::read_set(path)?;
        let set = specconv_spectral::TrainingSet::from_file(&table, &sha256, grid, w.hold_ends)?;
        let mut terms = match w.licences.get(k) {
            Some(licence) => Terms::stated(licence, Default::default())
                .map_err(|e| usage(anyhow::anyhow!("--licence: {e}")))?,
            None => {
                warn_named_like_known(path, &set, &sha256);
                set.sets[0].terms()
            }
        };
        if let Some(&c) = w.commercial.get(k) {
            terms.commercial = c;
        }
        parts.push(specconv_spectral::Part {
            weight: w.weights.get(k).copied().unwrap_or(1.0),
            terms,
            set,
        });
    }
    Ok(parts)
}

/// Says when a --spectra file without a stated licence takes a shared set's name without its
/// data: its terms are those of its content (`terms`), never that set's.
fn warn_named_like_known(path: &Path, set: &specconv_spectral::TrainingSet, sha256: &str) {
    use specconv_spectral::otsu2018::terms::named_like_known;
    let record = &set.sets[0];
    if let Some((known_count, known)) = named_like_known(&record.source, sha256) {
        errln!(
            "specconv: warning: {} is named like the shared set {} ({known_count} spectra, SHA-256 {known}) but holds other data ({} spectra, SHA-256 {sha256}), so its terms are not that set's but {:?}; state them with --licence and --commercial",
            specconv_atomic_file::shown::escaped(&path.display().to_string()),
            record.source,
            record.count,
            record.licence
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command_line::{Cli, Command};
    use clap::Parser;
    use specconv_spectral::otsu2018::blend::DEFAULT_WIDTH;

    fn parse(args: &[&str]) -> Command {
        let cli = Cli::try_parse_from([&["specconv"], args].concat()).unwrap();
        cli.command.expect("a subcommand")
    }

    /// `convert` and `simulate` given the same method options describe the same stack, at
    /// their defaults and with every option set.
    #[test]
    fn convert_and_simulate_describe_the_same_stack() {
        let options: [&[&str]; 3] = [
            &[],
            &["--blend", "0.05", "--unbounded", "--bands", "400:700:5"],
            &[
                "--blend",
                "0",
                "--unbounded",
                "--bounded",
                "--model",
                "m.json",
            ],
        ];
        for method in MethodName::ALL {
            for opts in options {
                let m = ["--method", method.as_str()];
                let Command::Convert(c) =
                    parse(&[&["convert", "a.png", "b.exr"], &m[..], opts].concat())
                else {
                    panic!("convert")
                };
                let Command::Simulate(s) =
                    parse(&[&["simulate", "--scene", "s.toml"], &m[..], opts].concat())
                else {
                    panic!("simulate")
                };
                assert_eq!(
                    c.options().stack_spec(),
                    s.stack_spec(method),
                    "{method} {opts:?}"
                );
                assert_eq!(c.options().model, s.stack.options.model);
            }
        }
        let Command::Convert(c) = parse(&["convert", "a.png", "b.exr"]) else {
            panic!("convert")
        };
        assert_eq!(
            c.options().stack_spec(),
            StackSpec::convert_default(MethodName::Otsu2018)
        );
        assert_eq!(c.options().stack_spec().blend, DEFAULT_WIDTH);
    }

    /// `eval` describes what `report` measures: the method on its own band sums, bounded only
    /// when asked.
    #[test]
    fn eval_describes_the_measured_method() {
        let Command::Eval(e) = parse(&[
            "eval",
            "--spectra",
            "s.csv",
            "--method",
            "smits1999",
            "--observer",
            "cie1964",
            "--bands",
            "400:700:10",
            "--bounded",
        ]) else {
            panic!("eval")
        };
        let setting = Setting {
            grid: Some(specconv_colour::Grid::new(400.0, 700.0, 10.0).unwrap()),
            observer: Some(specconv_colour::Observer::Cie1964),
            illuminant: None,
        };
        let want = StackSpec::measured(MethodName::Smits1999, DEFAULT_WIDTH, setting, 64, true);
        assert_eq!(e.stack_spec(), want);
        assert_eq!(
            want.exact_under,
            specconv_spectral::stack::ExactUnder::BandSums
        );
    }

    /// The colorimetry flags' defaults and the help's words for the built-in model's setting
    /// are the built-in model's own (issue 58: they are written as literals for clap).
    #[test]
    fn the_colorimetry_defaults_are_the_built_in_model_s_setting() {
        use clap::{CommandFactory, FromArgMatches, Parser};
        #[derive(Parser)]
        struct Fixed {
            #[command(flatten)]
            c: ColorimetryArgs,
        }
        #[derive(Parser)]
        struct WithModel {
            #[command(flatten)]
            s: SettingArgs,
        }
        let m = Model::builtin();
        let fixed = Fixed::from_arg_matches(&Fixed::command().get_matches_from(["x"])).unwrap();
        assert_eq!(
            (fixed.c.observer, fixed.c.illuminant, fixed.c.bands),
            (m.observer, m.illuminant, m.grid)
        );
        let help = WithModel::command().render_long_help().to_string();
        for (words, value) in [
            ("cie1931 for the built-in one", m.observer.to_string()),
            ("D65 for the built-in one", m.illuminant.to_string()),
            ("380:730:10 for the built-in", m.grid.to_string()),
        ] {
            assert!(help.contains(words), "{words}: {help}");
            assert!(words.starts_with(&value), "{words} is not {value}");
        }
    }
}
