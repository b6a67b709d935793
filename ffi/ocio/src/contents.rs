//! What a config holds beyond its active colour spaces: every colour space (inactive
//! ones too), roles, displays and their views, view transforms, looks, named transforms
//! and file rules, in config order, as OpenColorIO reads them.

use ocio_sys as sys;

use std::ptr::NonNull;

use crate::config::Config;
use crate::error::{Error, Result};
use crate::processor::{Processor, XyzRoute};
use crate::shim::{config_str, cstring, last_error};

/// One view of a display.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct View {
    /// The view's name.
    pub name: String,
    /// Empty for a view that names a colour space directly.
    pub view_transform: String,
    /// The display colour space, or `<USE_DISPLAY_NAME>` for shared views.
    pub color_space: String,
    /// The looks the view applies, as the config writes them; empty when none.
    pub looks: String,
}

/// One look.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Look {
    /// The look's name.
    pub name: String,
    /// The colour space the look is applied in.
    pub process_space: String,
}

/// One file rule.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FileRule {
    /// The rule's name.
    pub name: String,
    /// The colour space the rule gives matching files, as the config writes it.
    pub color_space: String,
    /// The glob pattern the file name must match, empty when the rule has none.
    pub pattern: String,
    /// The glob pattern the file extension must match, empty when the rule has none.
    pub extension: String,
    /// The regular expression the path must match, empty when the rule has none.
    pub regex: String,
}

impl Config {
    /// The items of one list of the shim, each split into its tab-separated fields.
    fn list(
        &self,
        kind: sys::specconv_ocio_list_kind,
        parent: Option<&str>,
    ) -> Result<Vec<Vec<String>>> {
        let c_parent = parent.map(cstring).transpose()?;
        let parent_ptr = c_parent.as_ref().map_or(std::ptr::null(), |p| p.as_ptr());
        let fail = || Error::ConfigLoad {
            origin: self.source().to_string(),
            message: last_error(),
        };
        let mut len = 0;
        // SAFETY: live config; parent is NULL or a valid C string; len is a valid out-pointer.
        let status = unsafe {
            sys::specconv_ocio_list_len(self.raw.as_ptr(), kind as i32, parent_ptr, &mut len)
        };
        if status as u32 != sys::SPECCONV_OCIO_OK {
            return Err(fail());
        }
        let mut items = Vec::with_capacity(len.max(0) as usize);
        for i in 0..len {
            let mut item = std::ptr::null();
            // SAFETY: as above, index below the length; the item is copied before the next
            // shim call on this thread.
            let status = unsafe {
                sys::specconv_ocio_list_item(
                    self.raw.as_ptr(),
                    kind as i32,
                    parent_ptr,
                    i,
                    &mut item,
                )
            };
            if status as u32 != sys::SPECCONV_OCIO_OK {
                return Err(fail());
            }
            items.push(config_str(item).split('\t').map(str::to_owned).collect());
        }
        Ok(items)
    }

    fn names(&self, kind: sys::specconv_ocio_list_kind) -> Result<Vec<String>> {
        Ok(self
            .list(kind, None)?
            .into_iter()
            .map(|mut fields| fields.swap_remove(0))
            .collect())
    }

    /// Every colour space's name, active and inactive, scene- and display-referred.
    pub fn all_color_space_names(&self) -> Result<Vec<String>> {
        self.names(sys::SPECCONV_OCIO_LIST_COLOR_SPACES)
    }

    /// Every role with the colour space it points to.
    pub fn roles(&self) -> Result<Vec<(String, String)>> {
        Ok(self
            .list(sys::SPECCONV_OCIO_LIST_ROLES, None)?
            .into_iter()
            .map(|f| (field(&f, 0), field(&f, 1)))
            .collect())
    }

    /// Every display, active or not.
    pub fn displays(&self) -> Result<Vec<String>> {
        self.names(sys::SPECCONV_OCIO_LIST_DISPLAYS)
    }

    /// The views of a display: its own, then the shared ones it uses.
    pub fn views(&self, display: &str) -> Result<Vec<View>> {
        Ok(self
            .list(sys::SPECCONV_OCIO_LIST_VIEWS, Some(display))?
            .into_iter()
            .map(|f| View {
                name: field(&f, 0),
                view_transform: field(&f, 1),
                color_space: field(&f, 2),
                looks: field(&f, 3),
            })
            .collect())
    }

    /// Every view transform's name.
    pub fn view_transforms(&self) -> Result<Vec<String>> {
        self.names(sys::SPECCONV_OCIO_LIST_VIEW_TRANSFORMS)
    }

    /// Every look.
    pub fn looks(&self) -> Result<Vec<Look>> {
        Ok(self
            .list(sys::SPECCONV_OCIO_LIST_LOOKS, None)?
            .into_iter()
            .map(|f| Look {
                name: field(&f, 0),
                process_space: field(&f, 1),
            })
            .collect())
    }

    /// Every named transform with its aliases.
    pub fn named_transforms(&self) -> Result<Vec<(String, Vec<String>)>> {
        Ok(self
            .list(sys::SPECCONV_OCIO_LIST_NAMED_TRANSFORMS, None)?
            .into_iter()
            .map(|mut f| {
                let name = f.remove(0);
                (name, f)
            })
            .collect())
    }

    /// A processor from colour space `src` to a view of a display: the view's looks and
    /// view transform, then the display's colour space.
    pub fn display_view_processor(
        &self,
        src: &str,
        display: &str,
        view: &str,
    ) -> Result<Processor> {
        let src = self.color_space(src)?.name;
        let target = format!("{display} / {view}");
        let (c_src, c_display, c_view) = (cstring(&src)?, cstring(display)?, cstring(view)?);
        let mut raw = std::ptr::null_mut();
        // SAFETY: live config, valid C strings, raw receives an owned processor on success.
        let status = unsafe {
            sys::specconv_ocio_display_view_processor_new(
                self.raw.as_ptr(),
                c_src.as_ptr(),
                c_display.as_ptr(),
                c_view.as_ptr(),
                &mut raw,
            )
        };
        match (status as u32, NonNull::new(raw)) {
            (sys::SPECCONV_OCIO_OK, Some(raw)) => Ok(Processor {
                raw,
                src,
                route: XyzRoute::Direct(target),
            }),
            _ => Err(Error::Processor {
                src,
                dst: target,
                message: last_error(),
            }),
        }
    }

    /// The file rules, the default rule last.
    pub fn file_rules(&self) -> Result<Vec<FileRule>> {
        Ok(self
            .list(sys::SPECCONV_OCIO_LIST_FILE_RULES, None)?
            .into_iter()
            .map(|f| FileRule {
                name: field(&f, 0),
                color_space: field(&f, 1),
                pattern: field(&f, 2),
                extension: field(&f, 3),
                regex: field(&f, 4),
            })
            .collect())
    }
}

fn field(fields: &[String], i: usize) -> String {
    fields.get(i).cloned().unwrap_or_default()
}
