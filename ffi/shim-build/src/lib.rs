//! What the `-sys` crates' build scripts and bindings tests share: each shim is
//! `shim/specconv_<name>.{h,cpp}` over one system library found by pkg-config.
#![forbid(unsafe_code)]

use std::path::PathBuf;

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
    /// A shared object of its own (`$OUT_DIR/libspecconv_<name>.so`), linked to the system
    /// library, that the `-sys` crate embeds and loads on first use: the program does not
    /// depend on the system library until then. The bindings are a table of function
    /// pointers resolved at load (bindgen's dynamic mode, struct `Specconv<Name>`, through
    /// `libloading`).
    Embedded,
}

/// specconv's shim over OpenImageIO: embedded, so that commands which read no image do not
/// load OpenImageIO's ≈260 libraries (issue 19).
pub const OIIO: Shim = Shim {
    name: "oiio",
    library: "OpenImageIO",
    min_version: "2.4",
    debian_package: "libopenimageio-dev",
    linking: Linking::Embedded,
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
    /// or as the shared object `$OUT_DIR/libspecconv_<name>.so` ([`Linking::Embedded`]),
    /// which links to the library itself while the program does not.
    pub fn build(&self) {
        let (header, source) = (
            format!("shim/specconv_{}.h", self.name),
            format!("shim/specconv_{}.cpp", self.name),
        );
        println!("cargo:rerun-if-changed={header}");
        println!("cargo:rerun-if-changed={source}");
        let embedded = self.linking == Linking::Embedded;
        if embedded {
            // What pkg-config's own metadata, turned off below, would have said.
            for var in [
                "PKG_CONFIG_PATH",
                "PKG_CONFIG_LIBDIR",
                "PKG_CONFIG_SYSROOT_DIR",
            ] {
                println!("cargo:rerun-if-env-changed={var}");
            }
        }
        let lib = match pkg_config::Config::new()
            .atleast_version(self.min_version)
            // Embedded: the shared object links the library, the program must not.
            .cargo_metadata(!embedded)
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
        };
        println!("cargo:version={}", lib.version);
        if embedded {
            // For the message that says which library to install when loading fails.
            println!(
                "cargo:rustc-env=SPECCONV_{}_BUILT_AGAINST={}",
                self.name.to_uppercase(),
                lib.version
            );
        }
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
        if !embedded {
            build.compile(&format!("specconv_{}_shim", self.name));
            return;
        }
        build.pic(true).cargo_metadata(false);
        let objects = build.compile_intermediates();
        let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
        let soname = format!("libspecconv_{}.so", self.name);
        // The compiler driver links, so the C++ runtime comes along as for any C++ library.
        // `-z defs`: a symbol the library does not provide fails here, not at first use.
        // `-z now`: the shim's own references are bound when it is loaded (as they were in
        // the program, which Rust links with `-z now`), so a library that lacks one fails
        // the load with dlopen's message; the system library's own dependencies keep their
        // lazy binding, as when the program loaded them at start. `--strip-debug`: the
        // program carries the object and copies it to memory when it loads it; DWARF was
        // 1.2 of its 1.3 MB.
        let mut link = build.get_compiler().to_command();
        link.arg("-shared")
            .arg("-o")
            .arg(out.join(&soname))
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

    /// For the bindings test: fails when `src/bindings.rs` under `crate_dir` is not what bindgen
    /// makes of the shim header; rewrites it instead when SPECCONV_REGENERATE_BINDINGS is set
    /// (ffi/regenerate-bindings.sh).
    #[cfg(feature = "bindings")]
    pub fn check_bindings(&self, crate_dir: &std::path::Path) {
        let header = format!("shim/specconv_{}.h", self.name);
        let prefix = format!("specconv_{}_.*", self.name);
        let mut builder = bindgen::Builder::default();
        if self.linking == Linking::Embedded {
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
