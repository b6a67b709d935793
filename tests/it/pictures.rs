//! PNG pictures: `report --plot FILE.png`, `simulate --image`, `preview`. Each is read back and
//! checked against what the command computed.

use crate::runner::*;
use std::collections::HashSet;
use std::path::Path;
use std::process::Command;

/// An 8-bit RGB picture read back from a PNG.
pub struct Picture {
    pub width: u32,
    pub height: u32,
    rgb: image::RgbImage,
}

impl Picture {
    pub fn read(path: &Path) -> Picture {
        let img = image::open(path)
            .unwrap_or_else(|e| panic!("{} is not a PNG: {e}", path.display()))
            .to_rgb8();
        Picture {
            width: img.width(),
            height: img.height(),
            rgb: img,
        }
    }

    pub fn at(&self, x: u32, y: u32) -> [u8; 3] {
        self.rgb.get_pixel(x, y).0
    }

    pub fn distinct_colours(&self) -> usize {
        self.rgb.pixels().map(|p| p.0).collect::<HashSet<_>>().len()
    }

    /// Pixels within `tol` of `c` in every channel.
    pub fn count_near(&self, c: [u8; 3], tol: u8) -> usize {
        self.rgb
            .pixels()
            .filter(|p| (0..3).all(|k| p.0[k].abs_diff(c[k]) <= tol))
            .count()
    }
}

#[test]
fn report_draws_its_plot_as_png() {
    let dir = Scratch::new("report-png");
    let plot = dir.path("cost.png");
    let cc = colorchecker();
    let out = Command::new(env!("CARGO_BIN_EXE_specconv"))
        .args(["report", "--spectra", cc.to_str().unwrap()])
        .args(["--clusters", "1,2", "--steps", "10", "--colours", "4096"])
        .args(["--jakob-resolution", "8", "-j", "1", "--json", "--plot"])
        .arg(&plot)
        .env("SPECCONV_CACHE_DIR", &dir.0)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let pic = Picture::read(&plot);
    assert_eq!((pic.width, pic.height), (900, 600));
    // White ground, black axes and text, antialiased edges, and a point in each method's
    // colour: otsu2018 red (over pca: one cluster is the same point), meng2015 green,
    // jakob2019 blue.
    assert!(pic.distinct_colours() > 20, "{}", pic.distinct_colours());
    assert!(pic.count_near([255, 255, 255], 0) > 900 * 600 / 2);
    assert!(rows.as_array().unwrap().len() >= 6);
    for c in [[255, 0, 0], [0, 255, 0], [0, 0, 255]] {
        assert!(pic.count_near(c, 10) >= 20, "no point in {c:?}");
    }
    // Only what was asked is in the directory: the PNG and the jakob2019 table cache.
    assert!(
        dir.files().iter().all(|f| !f.contains(".tmp")),
        "{:?}",
        dir.files()
    );
}
