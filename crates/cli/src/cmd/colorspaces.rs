//! `specconv colorspaces`: the colour spaces of an OCIO config.

use anyhow::Result;
use serde::Serialize;
use specconv_convert_cmd::checks::config;
use specconv_flags::defs;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv colorspaces
  specconv --ocio /show/config.ocio colorspaces --json
";

specconv_flags::args! {
    /// List the colour spaces of an OCIO config, with their aliases and the roles specconv
    /// uses.
    ///
    /// Any name or alias listed can be given to --colorspace. Data spaces (such as Raw) are
    /// listed but cannot be uplifted.
    #[derive(Debug)]
    pub struct Args {
        /// The global --ocio (see `specconv --help`).
        pub(crate) ocio: Option<String> = skip,
        json: bool = (defs::JSON_INSTEAD_OF_TEXT),
    }
}

/// Roles that decide how specconv reads and converts colours.
const ROLES: [&str; 5] = [
    "scene_linear",
    "cie_xyz_d65_interchange",
    "aces_interchange",
    "color_picking",
    "data",
];

#[derive(Serialize)]
struct Report {
    config: String,
    roles: Vec<Role>,
    color_spaces: Vec<Space>,
}

#[derive(Serialize)]
struct Role {
    role: &'static str,
    color_space: Option<String>,
}

#[derive(Serialize)]
struct Space {
    name: String,
    aliases: Vec<String>,
    family: String,
    encoding: String,
    reference: &'static str,
    is_data: bool,
}

pub fn run(args: Args) -> Result<()> {
    let config = config(args.ocio.as_deref())?;
    let mut roles = Vec::new();
    for role in ROLES {
        roles.push(Role {
            role,
            color_space: config.role(role)?,
        });
    }
    let report = Report {
        config: config.describe_origin(),
        roles,
        color_spaces: config
            .colour_spaces()?
            .into_iter()
            .map(|c| Space {
                name: c.name,
                aliases: c.aliases,
                family: c.family,
                encoding: c.encoding,
                reference: if c.is_display { "display" } else { "scene" },
                is_data: c.is_data,
            })
            .collect(),
    };
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&report)?)?;
        return Ok(());
    }
    outln!("config: {}", report.config)?;
    outln!()?;
    outln!("roles:")?;
    for r in &report.roles {
        outln!(
            "  {:<24} {}",
            r.role,
            r.color_space.as_deref().unwrap_or("(not defined)")
        )?;
    }
    outln!()?;
    outln!("colour spaces:")?;
    for c in &report.color_spaces {
        let mut notes = Vec::new();
        if c.is_data {
            notes.push("data, cannot be uplifted".to_owned());
        }
        if c.reference == "display" {
            notes.push("display-referred".to_owned());
        }
        let notes = if notes.is_empty() {
            String::new()
        } else {
            format!("  [{}]", notes.join("; "))
        };
        outln!("  {}{notes}", c.name)?;
        if !c.aliases.is_empty() {
            outln!("      aliases: {}", c.aliases.join(", "))?;
        }
    }
    Ok(())
}
