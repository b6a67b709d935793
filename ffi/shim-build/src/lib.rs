//! What the `-sys` crates' build scripts and bindings tests share: each shim is
//! `shim/specconv_<name>.{h,cpp}` over one system library found by pkg-config.
#![forbid(unsafe_code)]

use std::path::{Path, PathBuf};

/// One C++ shim and the system library it wraps.
pub struct Shim {
    /// `oiio` or `ocio`: the shim's file names and symbol prefix.
    pub name: &'static str,
    /// The pkg-config name, e.g. `OpenImageIO`.
    pub library: &'static str,
    pub min_version: &'static str,
    /// What to install on Debian when the library is missing.
    pub debian_package: &'static str,
    pub linking: Linking,
}

/// How a shim, and the system library under it, reach the program.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Linking {
    /// A static library linked into the program: the system library is loaded when the
    /// program starts, and the bindings are plain `extern "C"` declarations.
    Static,
    /// A shared object of its own, `libspecconv_<name>.so`, linked to the system library and
    /// installed beside the program, which the `-sys` crate opens on first use: the program
    /// does not depend on the system library until then. The bindings are a table of function
    /// pointers resolved at load (bindgen's dynamic mode, struct `Specconv<Name>`, through
    /// `libloading`). See [`Shim::build`] for where the object is put.
    Dynamic,
}

/// specconv's shim over OpenImageIO: a shared object loaded on first use, so that commands
/// which read no image do not load OpenImageIO's ≈260 libraries (issue 19).
pub const OIIO: Shim = Shim {
    name: "oiio",
    library: "OpenImageIO",
    min_version: "2.4",
    debian_package: "libopenimageio-dev",
    linking: Linking::Dynamic,
};

/// specconv's shim over OpenColorIO.
pub const OCIO: Shim = Shim {
    name: "ocio",
    library: "OpenColorIO",
    min_version: "2.1",
    debian_package: "libopencolorio-dev",
    linking: Linking::Static,
};

impl Shim {
    /// For build.rs: probes the library (exiting with an install hint when it is missing) and
    /// compiles the shim as C++17 against it: linked into the program ([`Linking::Static`]),
    /// or ([`Linking::Dynamic`]) as the shared object `libspecconv_<name>.so`, which links to
    /// the library itself while the program does not.
    ///
    /// A dynamic shim is linked in `$OUT_DIR` and copied to where cargo puts what it builds
    /// ([`install_dirs`]), so that `target/<profile>/specconv`, `cargo run`, tests, benches
    /// and examples find it beside them. It also gets an id, a hash of its header and source
    /// that the shared object exports as `specconv_<name>_shim_id`: the `-sys` crate refuses a
    /// shim of another build before calling any of its functions. For the crates that depend
    /// on the `-sys` crate directly, build.rs says where the object is (`cargo:shim=PATH`, read
    /// as `DEP_SPECCONV_<NAME>_SHIM`: the Python package copies it next to its module).
    pub fn build(&self) {
        let (header, source) = (
            format!("shim/specconv_{}.h", self.name),
            format!("shim/specconv_{}.cpp", self.name),
        );
        println!("cargo:rerun-if-changed={header}");
        println!("cargo:rerun-if-changed={source}");
        let lib = self.probe();
        println!("cargo:version={}", lib.version);
        let mut build = cc::Build::new();
        build
            .cpp(true)
            .std("c++17")
            .file(&source)
            .include("shim")
            .warnings(true);
        for dir in &lib.include_paths {
            build.include(dir);
        }
        for (name, value) in &lib.defines {
            build.define(name, value.as_deref());
        }
        match self.linking {
            Linking::Static => build.compile(&format!("specconv_{}_shim", self.name)),
            Linking::Dynamic => self.build_shared(build, &lib, (&header, &source)),
        }
    }

    /// The library through pkg-config; exits with what to install when it is missing.
    fn probe(&self) -> pkg_config::Library {
        let dynamic = self.linking == Linking::Dynamic;
        if dynamic {
            // What pkg-config's own metadata, turned off below, would have said.
            for var in [
                "PKG_CONFIG_PATH",
                "PKG_CONFIG_LIBDIR",
                "PKG_CONFIG_SYSROOT_DIR",
            ] {
                println!("cargo:rerun-if-env-changed={var}");
            }
        }
        match pkg_config::Config::new()
            .atleast_version(self.min_version)
            // Dynamic: the shared object links the library, the program must not.
            .cargo_metadata(!dynamic)
            .probe(self.library)
        {
            Ok(lib) => lib,
            Err(e) => {
                // A bare pkg-config failure does not say what to install; this does.
                eprintln!(
                    "error: {} >= {} was not found through pkg-config.\n\
                     On Debian/Ubuntu install it with:\n    \
                     sudo apt-get install {} pkg-config\n\
                     Elsewhere, point PKG_CONFIG_PATH at the directory holding {}.pc.\n\
                     pkg-config said: {e}",
                    self.library, self.min_version, self.debian_package, self.library
                );
                std::process::exit(1);
            }
        }
    }

    /// A dynamic shim: `build` with its id compiled in, linked as `libspecconv_<name>.so`
    /// against `lib`, and copied beside cargo's programs.
    fn build_shared(
        &self,
        mut build: cc::Build,
        lib: &pkg_config::Library,
        (header, source): (&str, &str),
    ) {
        let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
        let upper = self.name.to_uppercase();
        // For the message that says which library to install when loading fails.
        println!(
            "cargo:rustc-env=SPECCONV_{upper}_BUILT_AGAINST={}",
            lib.version
        );
        let read =
            |path: &str| std::fs::read(path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"));
        let id = shim_id(&[&read(header), &read(source)]);
        println!("cargo:rustc-env=SPECCONV_{upper}_SHIM_ID={id}");
        // Generated, so that the id never appears in the header (nor in the bindings).
        let id_source = out.join(format!("specconv_{}_shim_id.cpp", self.name));
        std::fs::write(
            &id_source,
            format!(
                "// Generated by specconv-shim-build: which build of the shim this is.\n\
                 extern \"C\" __attribute__((visibility(\"default\"))) \
                 const char specconv_{}_shim_id[] = \"{id}\";\n",
                self.name
            ),
        )
        .expect("OUT_DIR is writable");
        build.file(&id_source).pic(true).cargo_metadata(false);
        let soname = format!("libspecconv_{}.so", self.name);
        let built = out.join(&soname);
        link_shared(&build, lib, &soname, &built);
        println!("cargo:shim={}", built.display());
        match install_dirs(&out) {
            Some(dirs) => {
                for dir in dirs {
                    copy_replacing(&built, &dir.join(&soname));
                }
            }
            None => println!(
                "cargo:warning=OUT_DIR ({}) is not where cargo's layout puts it: {soname} was \
                 not copied beside the programs; copy {} there",
                out.display(),
                built.display()
            ),
        }
    }

    #[cfg(feature = "bindings")]
    pub fn check_bindings(&self, crate_dir: &std::path::Path) {
        let header = format!("shim/specconv_{}.h", self.name);
        let prefix = format!("specconv_{}_.*", self.name);
        let mut builder = bindgen::Builder::default();
        if self.linking == Linking::Dynamic {
            // `Specconv<Name>`: the functions as a table of pointers, all resolved at load.
            let mut name = self.name.to_owned();
            name[..1].make_ascii_uppercase();
            builder = builder
                .dynamic_library_name(format!("Specconv{name}"))
                .dynamic_link_require_all(true);
        }
        let generated = builder
            .header(crate_dir.join(&header).to_str().expect("a UTF-8 path"))
            .allowlist_function(&prefix)
            .allowlist_type(&prefix)
            .allowlist_var(format!("SPECCONV_{}_.*", self.name.to_uppercase()))
            .default_enum_style(bindgen::EnumVariation::Consts)
            .prepend_enum_name(false)
            .formatter(bindgen::Formatter::Prettyplease)
            .raw_line(format!(
                "// Generated by bindgen from {header}; do not edit."
            ))
            .raw_line("// Regenerate with ffi/regenerate-bindings.sh.")
            .generate()
            .unwrap_or_else(|e| panic!("bindgen failed on {header}: {e}"))
            .to_string();
        let committed_path = crate_dir.join("src/bindings.rs");
        if std::env::var_os("SPECCONV_REGENERATE_BINDINGS").is_some() {
            std::fs::write(&committed_path, &generated).expect("src/bindings.rs is writable");
            return;
        }
        let committed = std::fs::read_to_string(&committed_path).unwrap_or_default();
        assert!(
            committed == generated,
            "src/bindings.rs is stale: the shim header changed. Run ffi/regenerate-bindings.sh"
        );
    }
}

/// Compiles `build`'s sources and links them as the shared object `built` (named `soname`)
/// against `lib`.
fn link_shared(build: &cc::Build, lib: &pkg_config::Library, soname: &str, built: &Path) {
    let objects = build.compile_intermediates();
    // The compiler driver links, so the C++ runtime comes along as for any C++ library.
    // `-z defs`: a symbol the library does not provide fails here, not at first use.
    // `-z now`: the shim's own references are bound when it is loaded (as they were in
    // the program, which Rust links with `-z now`), so a library that lacks one fails
    // the load with dlopen's message; the system library's own dependencies keep their
    // lazy binding, as when the program loaded them at start. `--strip-debug`: the object
    // is installed beside every program and package; DWARF was 1.2 of its 1.3 MB.
    let mut link = build.get_compiler().to_command();
    link.arg("-shared")
        .arg("-o")
        .arg(built)
        .args(&objects)
        .arg(format!("-Wl,-soname,{soname}"))
        .args(["-Wl,-z,defs", "-Wl,-z,now", "-Wl,-z,relro"])
        .args(["-Wl,--as-needed", "-Wl,-O1", "-Wl,--strip-debug"]);
    for dir in &lib.link_paths {
        link.arg("-L").arg(dir);
    }
    for name in &lib.libs {
        link.arg(format!("-l{name}"));
    }
    for args in &lib.ld_args {
        link.arg(format!("-Wl,{}", args.join(",")));
    }
    let status = link
        .status()
        .unwrap_or_else(|e| panic!("cannot run the linker for {soname}: {e}"));
    assert!(status.success(), "linking {soname} failed: {link:?}");
}

/// Where cargo puts the programs built with the build script whose `OUT_DIR` is `out`: the
/// profile's folder (`target/<profile>/`, binaries and `cargo run`), its `deps/` (tests and
/// benches) and `examples/`. Cargo's layout is not a documented interface, but it has been
/// the same since 1.0: `OUT_DIR` is `<target>/<profile>/build/<package>-<hash>/out`
/// (`<target>/<triple>/<profile>/…` with `--target`), so the profile's folder is three up.
/// `None` where `out` is not laid out so (a `build.build-dir` set apart from the target
/// folder puts it elsewhere).
pub fn install_dirs(out: &Path) -> Option<Vec<PathBuf>> {
    let build = out.parent()?.parent()?;
    if out.file_name()? != "out" || build.file_name()? != "build" {
        return None;
    }
    let profile = build.parent()?;
    Some(vec![
        profile.to_owned(),
        profile.join("deps"),
        profile.join("examples"),
    ])
}

/// Copies `from` to `to` through a temporary name and a rename, keeping `from`'s modification
/// time (as `cp -p`: a build script can watch the copy with `rerun-if-changed` without
/// rerunning on every build). A program that has the old object mapped keeps it, where writing
/// over it in place would change its code under it.
pub fn copy_replacing(from: &Path, to: &Path) {
    let dir = to.parent().expect("a file in a folder");
    let temporary = dir.join(format!(
        ".{}.{}.tmp",
        to.file_name().expect("a file name").to_string_lossy(),
        std::process::id()
    ));
    let copied = std::fs::create_dir_all(dir)
        .and_then(|()| std::fs::copy(from, &temporary))
        .and_then(|_| {
            let modified = std::fs::metadata(from)?.modified()?;
            std::fs::File::options()
                .write(true)
                .open(&temporary)?
                .set_modified(modified)
        })
        .and_then(|()| std::fs::rename(&temporary, to));
    if let Err(e) = copied {
        let _ = std::fs::remove_file(&temporary);
        panic!("cannot copy {} to {}: {e}", from.display(), to.display());
    }
}

/// A shim's id: FNV-1a (64 bits) over its files, in hex. It tells builds apart; it is no
/// defence against a forged object (whoever can write beside the program can run code).
fn shim_id(files: &[&[u8]]) -> String {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for file in files {
        for &byte in file.iter().chain(&(file.len() as u64).to_le_bytes()) {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    format!("{hash:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_programs_folders_are_three_up_from_out_dir() {
        let out = Path::new("/w/target/release/build/oiio-sys-0123abcd/out");
        assert_eq!(
            install_dirs(out).unwrap(),
            [
                Path::new("/w/target/release"),
                Path::new("/w/target/release/deps"),
                Path::new("/w/target/release/examples"),
            ]
        );
        let cross = Path::new("/w/target/x86_64-unknown-linux-gnu/debug/build/oiio-sys-1/out");
        assert_eq!(
            install_dirs(cross).unwrap()[0],
            Path::new("/w/target/x86_64-unknown-linux-gnu/debug")
        );
        assert_eq!(install_dirs(Path::new("/somewhere/else/out")), None);
        assert_eq!(install_dirs(Path::new("/w/target/debug/build/x")), None);
    }

    #[test]
    fn ids_tell_files_apart_and_are_stable() {
        let id = shim_id(&[b"header", b"source"]);
        assert_eq!(id.len(), 16);
        assert_eq!(id, shim_id(&[b"header", b"source"]));
        assert_ne!(id, shim_id(&[b"header", b"sourcf"]));
        // Moving a byte from one file to the other is another shim.
        assert_ne!(id, shim_id(&[b"headers", b"ource"]));
        // FNV-1a's published test vector: the empty input hashes to the offset basis.
        assert_eq!(shim_id(&[]), "cbf29ce484222325");
    }
}
