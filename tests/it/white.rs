//! Issue 55: white is white. The perfect white is a vertex of the object-colour solid, and the
//! only reflectance with its colour is r ≡ 1 (a band below 1 lowers some tristimulus value).
//! Whatever encoding and colour space a texture's white comes in, every band written is
//! exactly 1, read back by OpenImageIO's own reader.

use crate::runner::*;

/// Every `T.*` sample of `exr`, as OpenImageIO reads them, with the pixel's index.
fn reflectance_samples(exr: &std::path::Path) -> Vec<(usize, f32)> {
    let code = "import sys, OpenImageIO as oiio\n\
        i = oiio.ImageInput.open(sys.argv[1]); s = i.spec()\n\
        px = i.read_image(0, 0, 0, s.nchannels, 'float').reshape(-1, s.nchannels)\n\
        t = [k for k, n in enumerate(s.channelnames) if n.startswith('T.')]\n\
        assert len(t) == 36, s.channelnames\n\
        for p, row in enumerate(px):\n\
        \x20   print(p, ' '.join(repr(float(row[k])) for k in t))\n";
    let out = python_output(["-c", code, exr.to_str().unwrap()]);
    String::from_utf8(out)
        .unwrap()
        .lines()
        .flat_map(|l| {
            let mut w = l.split(' ');
            let p: usize = w.next().unwrap().parse().unwrap();
            w.map(move |v| (p, v.parse::<f32>().unwrap()))
                .collect::<Vec<_>>()
        })
        .collect()
}

#[test]
fn white_in_every_encoding_and_space_is_the_perfect_reflector() {
    let dir = Scratch::new("white");
    // (data type, file, colour space, value): 8- and 16-bit sRGB textures, half and float
    // linear Rec.709 and ACEScg, and a float white a hair above 1.
    let cases = [
        ("uint8", "w8.png", "sRGB - Texture", "1"),
        ("uint16", "w16.tif", "sRGB - Texture", "1"),
        ("half", "wh.exr", "Linear Rec.709 (sRGB)", "1"),
        ("float", "wf.exr", "ACEScg", "1"),
        ("float", "wl.exr", "Linear Rec.2020", "1"),
        ("float", "wa.exr", "Linear Rec.709 (sRGB)", "1.0001"),
    ];
    for (kind, name, space, v) in cases {
        let input = dir.path(name);
        let colour = format!("constant:color={v},{v},{v}");
        tool(
            "oiiotool",
            &[
                "--pattern",
                &colour,
                "8x8",
                "3",
                "-d",
                kind,
                "-o",
                input.to_str().unwrap(),
            ],
        );
        for sample in ["half", "float"] {
            let out = dir.path(&format!("{name}-{sample}.exr"));
            Cmd::convert(&input, &out)
                .args(["--ocio", "aces", "--colorspace", space, "-d", sample])
                .ok();
            let samples = reflectance_samples(&out);
            assert_eq!(samples.len(), 64 * 36, "{name} {sample}");
            let off: Vec<_> = samples.iter().filter(|(_, v)| *v != 1.0).collect();
            assert!(off.is_empty(), "{name} ({space}) as {sample}: {off:?}");
        }
    }
}

/// White among other colours (not a constant image, which the constant detection makes
/// cheap): the white pixels are r ≡ 1 exactly, the others are not moved onto white.
#[test]
fn white_pixels_of_a_varied_texture_are_the_perfect_reflector() {
    let dir = Scratch::new("white-varied");
    let input = dir.path("mixed.png");
    let noise = dir.path("noise.png");
    tool(
        "oiiotool",
        &[
            "--pattern",
            "noise:type=uniform:min=0:max=0.95",
            "16x8",
            "3",
            "-d",
            "uint8",
            "-o",
            noise.to_str().unwrap(),
        ],
    );
    // Left half white, right half noise below white.
    tool(
        "oiiotool",
        &[
            noise.to_str().unwrap(),
            "--pattern",
            "constant:color=1,1,1",
            "16x16",
            "3",
            "--paste",
            "+0+8",
            "-d",
            "uint8",
            "-o",
            input.to_str().unwrap(),
        ],
    );
    let out = dir.path("mixed.exr");
    Cmd::convert(&input, &out)
        .args(["--ocio", "aces", "-d", "float"])
        .ok();
    let samples = reflectance_samples(&out);
    let mut white = [true; 256];
    for &(p, v) in &samples {
        white[p] &= v == 1.0;
    }
    // Rows 0–7 are white: every band 1. Rows 8–15 hold the noise: none of them is white.
    assert!(white[..128].iter().all(|&w| w), "{white:?}");
    assert!(white[128..].iter().all(|&w| !w), "{white:?}");
}
