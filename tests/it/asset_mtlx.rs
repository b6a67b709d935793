//! `specconv asset` on MaterialX documents (issue 46, docs/assets.md): documents built with the
//! MaterialX package (tests/asset_mtlx.py), each image decided by the shader input its graph
//! feeds, and the override copy read back with MaterialX (the USD layer with usd-core). Without
//! usd-core and MaterialX in `$SPECCONV_PYTHON` these tests are skipped, loudly, unless
//! `$SPECCONV_REQUIRE_USD` is set (CI sets it).

use crate::asset::{python_with, record, roles_with_textures};
use crate::runner::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The interpreter with usd-core and MaterialX, or `None` (skip) when it lacks one.
fn mtlx() -> Option<String> {
    python_with("pxr.Usd, MaterialX", "usd-core MaterialX")
}

/// The textures (oiiotool), then the documents of `kind` in `dir`.
fn documents(dir: &Path, kind: &str) {
    let tex = dir.join("tex");
    std::fs::create_dir_all(&tex).unwrap();
    for name in [
        "brick_color",
        "brick_arm",
        "brick_normal",
        "brick_height",
        "wood.1001",
        "wood.1002",
        "rock_albedo",
        "shared",
        "never",
    ] {
        let p = tex.join(format!("{name}.png"));
        let p = p.to_str().unwrap();
        tool(
            "oiiotool",
            &["--pattern", "checker", "8x8", "4", "-d", "uint8", "-o", p],
        );
    }
    script("asset_mtlx.py", [kind, dir.to_str().unwrap()]);
}

fn asset(python: &str, doc: &Path, out: &Path) -> Cmd {
    Cmd::new(["asset", doc.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .env("SPECCONV_USD_PYTHON", python)
}

/// Every file under `dir` with its bytes.
fn tree(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut v = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return v;
    };
    for e in entries {
        let p = e.unwrap().path();
        let m = std::fs::symlink_metadata(&p).unwrap();
        if m.is_dir() {
            v.extend(tree(&p));
        } else if m.is_file() {
            v.push((p.clone(), std::fs::read(&p).unwrap()));
        }
    }
    v.sort();
    v
}

/// What MaterialX makes of an override copy: each image node's file input (any node with a
/// `file` input: `image`, `gltf_colorimage`…; value, colour
/// space, the recorded originals, the file it finds from the copy's folder) and whether the
/// document is valid against MaterialX's standard library.
fn copy_files(python: &str, doc: &Path) -> Value {
    let code = "import json, os, sys\n\
        import MaterialX as mx\n\
        d = mx.createDocument()\n\
        mx.readFromXmlFile(d, sys.argv[1])\n\
        lib = mx.createDocument()\n\
        mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)\n\
        d.setDataLibrary(lib)\n\
        out = {}\n\
        for e in d.traverseTree():\n\
        \x20   if e.isA(mx.Node) and e.getInput('file') is not None:\n\
        \x20       i = e.getInput('file')\n\
        \x20       v = i.getValueString()\n\
        \x20       found = os.path.join(os.path.dirname(sys.argv[1]), v)\n\
        \x20       out[e.getNamePath()] = dict(file=v, cs=i.getActiveColorSpace(),\n\
        \x20           original=i.getAttribute('specconv_original') or None,\n\
        \x20           original_cs=i.getAttribute('specconv_original_colorspace') or None,\n\
        \x20           exists=os.path.isfile(found.replace('<UDIM>', '1001')))\n\
        print(json.dumps(dict(files=out, valid=d.validate()[0],\n\
        \x20   source=d.getAttribute('specconv_source'))))\n";
    let out = std::process::Command::new(python)
        .args(["-c", code, doc.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    json(&String::from_utf8_lossy(&out.stdout))
}

#[test]
fn a_materialx_document_is_decided_by_its_graph_and_gets_an_override_copy() {
    let Some(python) = mtlx() else { return };
    let dir = Scratch::new("mtlx-brick");
    documents(&dir.0, "brick");
    let before = tree(&dir.0);
    let out = dir.path("out");
    let records = asset(&python, &dir.path("brick.mtlx"), &out)
        .arg("--json")
        .ok()
        .json_lines();
    // Four files of the brick, two UDIM tiles of the included wood; `never` is read by no
    // material.
    assert_eq!(records.len(), 6, "{records:#?}");
    assert!(!records
        .iter()
        .any(|r| r["input"].as_str().unwrap().contains("never")));
    // The image's colorspace (on the node graph's input its file comes through) names sRGB;
    // its alpha, taken out by `extract` and fed to opacity, keeps it one colour texture.
    let colour = record(&records, "brick_color.png");
    assert_eq!(colour["status"], "ok", "{colour:#}");
    assert_eq!(colour["colorspace"], "sRGB - Texture");
    assert_eq!(colour["asset"]["rule"], "materialx-colorspace");
    let why = colour["asset"]["why"].as_str().unwrap();
    assert!(
        why.contains("with alpha") && why.contains("SR_brick.base_color"),
        "{why}"
    );
    let use0 = &colour["asset"]["uses"][0];
    assert_eq!(
        (&use0["prim"], &use0["shader"]),
        (&json("\"NG_brick/color\""), &json("\"SR_brick\""))
    );
    // separate3's channels into roughness and metalness, a normal map through normalmap, a
    // height into displacement: data, never uplifted.
    for data in ["brick_arm.png", "brick_normal.png", "brick_height.png"] {
        let r = record(&records, data);
        assert_eq!(
            (&r["status"], &r["asset"]["rule"]),
            (&json("\"data\""), &json("\"data-input\"")),
            "{r:#}"
        );
    }
    let arm = &record(&records, "brick_arm.png")["asset"]["uses"];
    let channels: Vec<(&str, &str)> = arm
        .as_array()
        .unwrap()
        .iter()
        .map(|u| (u["input"].as_str().unwrap(), u["output"].as_str().unwrap()))
        .collect();
    assert_eq!(channels, [("metalness", "b"), ("specular_roughness", "g")]);
    // The XInclude's image: its own fileprefix, a <UDIM> pattern, ACEScg named outright.
    let wood = record(&records, "wood.<UDIM>.png");
    assert_eq!(
        (&wood["colorspace"], &wood["asset"]["rule"]),
        (&json("\"ACEScg\""), &json("\"materialx-colorspace\""))
    );
    assert!(out.join("tex/wood_spectral.1002.exr").is_file());
    // The originals are untouched; everything written is under DIR.
    let after: Vec<_> = tree(&dir.0)
        .into_iter()
        .filter(|(p, _)| !p.starts_with(&out))
        .collect();
    assert_eq!(before, after);
    no_temporaries(&out);
    // The copy, read by MaterialX: colour images at their spectral files, read in the working
    // space, the originals recorded; data images at their original files, absolute.
    let copy = copy_files(&python, &out.join("brick_spectral.mtlx"));
    assert_eq!(copy["valid"], true, "{copy:#}");
    assert_eq!(copy["source"], dir.path("brick.mtlx").to_str().unwrap());
    let files = &copy["files"];
    let c = &files["NG_brick/color"];
    assert_eq!(c["file"], "./tex/brick_color_spectral.exr");
    assert_eq!(
        (&c["cs"], &c["original"], &c["original_cs"]),
        (
            &json("\"lin_rec709\""),
            &json("\"brick_color.png\""),
            &json("\"srgb_texture\"")
        )
    );
    assert_eq!(c["exists"], true);
    assert_eq!(
        files["wood_color"]["file"],
        "./tex/wood_spectral.<UDIM>.exr"
    );
    assert_eq!(files["wood_color"]["exists"], true);
    let arm = &files["NG_brick/arm"];
    assert_eq!(arm["file"], dir.path("tex/brick_arm.png").to_str().unwrap());
    assert!(arm["original"].is_null());
    // A second run with -u converts nothing and writes the copy again.
    let again = asset(&python, &dir.path("brick.mtlx"), &out)
        .args(["--json", "-u"])
        .ok()
        .json_lines();
    assert!(again
        .iter()
        .all(|r| r["status"] == "skipped" || r["status"] == "data"));
    // Without -u the copy is not replaced.
    asset(&python, &dir.path("brick.mtlx"), &out).fails(2, &["brick_spectral.mtlx exists"]);
}

/// Issue 57, items 1 and 2: `asset` never replaces a file it did not write, nor one the
/// document reads, whatever -u and --force say; its own files it replaces as asked, unless
/// someone changed them since (the record in DIR, `specconv_asset::record`).
#[test]
fn asset_never_replaces_what_it_did_not_write_or_what_it_reads() {
    let Some(python) = mtlx() else { return };
    let dir = Scratch::new("mtlx-own");
    documents(&dir.0, "brick");
    let doc = dir.path("brick.mtlx");
    let out = dir.path("out");
    std::fs::create_dir_all(&out).unwrap();
    let theirs = out.join("brick_spectral.mtlx");
    std::fs::write(&theirs, "<!-- mine -->").unwrap();
    for flags in [&[][..], &["-u"], &["--force"]] {
        asset(&python, &doc, &out)
            .args(flags)
            .fails(2, &["brick_spectral.mtlx", "did not write it"]);
        assert_eq!(std::fs::read_to_string(&theirs).unwrap(), "<!-- mine -->");
        assert!(!out.join("tex").exists(), "{flags:?}: converted");
    }
    // Moved away: written, and replaced by a later -u run as its own.
    std::fs::remove_file(&theirs).unwrap();
    asset(&python, &doc, &out).ok();
    asset(&python, &doc, &out).arg("-u").ok();
    asset(&python, &doc, &out)
        .run()
        .fails(2, &["brick_spectral.mtlx exists", "-u"]);
    // Its own copy edited by hand since: kept, -u or --force.
    std::fs::write(&theirs, "<!-- edited by hand -->").unwrap();
    for flag in ["-u", "--force"] {
        asset(&python, &doc, &out)
            .arg(flag)
            .fails(2, &["brick_spectral.mtlx", "changed since"]);
        assert_eq!(
            std::fs::read_to_string(&theirs).unwrap(),
            "<!-- edited by hand -->"
        );
    }
    // A document that XIncludes the name of its own override copy, converted into its own
    // folder: the copy would be written over an input, with any flag.
    let text = std::fs::read_to_string(&doc).unwrap();
    assert!(text.contains("lib/wood.mtlx"), "{text}");
    let own = dir.path("b.mtlx");
    std::fs::write(&own, text.replace("lib/wood.mtlx", "b_spectral.mtlx")).unwrap();
    let included = dir.path("b_spectral.mtlx");
    std::fs::copy(dir.path("lib/wood.mtlx"), &included).unwrap();
    let before = std::fs::read(&included).unwrap();
    for flags in [&[][..], &["-u"], &["--force"]] {
        asset(&python, &own, &dir.0)
            .args(flags)
            .fails(2, &["b_spectral.mtlx is a file the stage reads"]);
        assert_eq!(std::fs::read(&included).unwrap(), before, "{flags:?}");
    }
}

#[test]
fn a_stage_referencing_a_materialx_document_merges_its_decisions() {
    let Some(python) = mtlx() else { return };
    let dir = Scratch::new("mtlx-stage");
    documents(&dir.0, "stage");
    let out = dir.path("out");
    let records = asset(&python, &dir.path("shot.usda"), &out)
        .arg("--json")
        .ok()
        .json_lines();
    // The referenced material's four files, the UsdPreviewSurface's albedo, and the wood's
    // two tiles (M_wood, bound through a scope that references two documents); not extra.mtlx's
    // image (no binding names M_extra).
    assert_eq!(records.len(), 7, "{records:#?}");
    let wood = record(&records, "wood.<UDIM>.png");
    assert_eq!(wood["asset"]["rule"], "materialx-colorspace");
    assert_eq!(
        wood["asset"]["uses"][0]["material"],
        "/World/Lib/Materials/M_wood"
    );
    let colour = record(&records, "brick_color.png");
    assert_eq!(colour["asset"]["rule"], "materialx-colorspace");
    assert_eq!(colour["asset"]["uses"][0]["material"], "/World/Looks/Brick");
    assert_eq!(record(&records, "brick_arm.png")["status"], "data");
    assert_eq!(
        record(&records, "rock_albedo.png")["asset"]["rule"],
        "colour-input"
    );
    // usd-core on the layer (issue 56, item 1): with no choice made, the references are the
    // stage's own (brick.mtlx twice, extra.mtlx: this usd-core cannot open them, so each is a
    // composition error naming it) and the USD texture node is untouched; with the variant
    // `spectralTextures = spectral` chosen on every prim that has it, each prim referencing
    // brick.mtlx also references its copy (the copy's opinions the stronger), and the USD
    // texture node has its copy in the spectral render context.
    let code = "import json, sys\n\
        from pxr import Usd\n\
        s = Usd.Stage.Open(sys.argv[1])\n\
        get = lambda p: s.GetPrimAtPath(p).GetAttribute('inputs:file').Get().path\n\
        before = [str(e) for e in s.GetCompositionErrors()]\n\
        switched = []\n\
        for p in list(s.TraverseAll()):\n\
        \x20   v = p.GetVariantSets()\n\
        \x20   if v.HasVariantSet('spectralTextures'):\n\
        \x20       switched.append(str(p.GetPath()))\n\
        \x20       v.GetVariantSet('spectralTextures').SetVariantSelection('spectral')\n\
        print(json.dumps(dict(before=before, after=[str(e) for e in s.GetCompositionErrors()],\n\
        \x20   switched=switched, rock=get('/World/Looks/Rock/Albedo_spectral'),\n\
        \x20   rgb=get('/World/Looks/Rock/Albedo'))))\n";
    let layer = out.join("shot_spectral.usda");
    let got = std::process::Command::new(&python)
        .args(["-c", code, layer.to_str().unwrap()])
        .output()
        .unwrap();
    let v = json(&String::from_utf8_lossy(&got.stdout));
    assert_eq!(v["rock"], "./tex/rock_albedo_spectral.exr", "{v:#}");
    assert_eq!(v["rgb"], "./tex/rock_albedo.png", "{v:#}");
    let errors = |key: &str| -> Vec<String> {
        v[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e.as_str().unwrap().to_owned())
            .collect()
    };
    let named = |errors: &[String], p: &Path| {
        errors
            .iter()
            .filter(|e| e.contains(&format!("@{}@", p.display())))
            .count()
    };
    let copy = out.join("brick_spectral.mtlx");
    let (before, after) = (errors("before"), errors("after"));
    assert_eq!(before.len(), 3, "{before:?}");
    assert_eq!(named(&before, &dir.path("brick.mtlx")), 2, "{before:?}");
    assert_eq!(named(&before, &dir.path("extra.mtlx")), 1, "{before:?}");
    assert_eq!(named(&before, &copy), 0, "{before:?}");
    // extra.mtlx has no copy (nothing of it is converted): its prim's reference is as it was.
    assert_eq!(v["switched"].as_array().unwrap().len(), 2, "{v:#}");
    assert_eq!(after.len(), 5, "{after:?}");
    assert_eq!(named(&after, &copy), 2, "{after:?}");
    assert_eq!(named(&after, &dir.path("brick.mtlx")), 2, "{after:?}");
    let copy = copy_files(&python, &out.join("brick_spectral.mtlx"));
    assert_eq!(
        copy["files"]["NG_brick/color"]["file"],
        "./tex/brick_color_spectral.exr"
    );
    assert_eq!(copy["files"]["NG_brick/color"]["exists"], true);
    // A referenced document MaterialX cannot read: the error names it and the prim; the
    // layer and the copy written before stay as they were.
    let layer_before = std::fs::read(&layer).unwrap();
    std::fs::write(dir.path("extra.mtlx"), "<materialx version=\"1.39\">").unwrap();
    asset(&python, &dir.path("shot.usda"), &out)
        .arg("-u")
        .fails(
            1,
            &[
                "MaterialX cannot read",
                "extra.mtlx",
                "referenced by /World/Lib",
            ],
        );
    assert_eq!(std::fs::read(&layer).unwrap(), layer_before);
}

#[test]
fn a_materialx_conflict_and_a_missing_image_name_their_nodes() {
    let Some(python) = mtlx() else { return };
    let dir = Scratch::new("mtlx-conflict");
    documents(&dir.0, "conflict");
    let out = dir.path("out");
    asset(&python, &dir.path("conflict.mtlx"), &out).fails(
        1,
        &[
            "shared_colour",
            "it runs through shared_red",
            "base_color",
            "specular_roughness",
            "not converted",
        ],
    );
    assert!(!out.join("tex/shared_spectral.exr").exists());
    asset(&python, &dir.path("conflict.mtlx"), &dir.path("out2"))
        .args(["--dry-run"])
        .fails(
            1,
            &[
                "gone",
                &format!(
                    "(looked for at {})",
                    dir.path("tex/no_such_file.png").display()
                ),
                "does not exist",
            ],
        );
}

#[test]
fn hostile_materialx_documents_fail_cleanly_inside_dir() {
    let Some(python) = mtlx() else { return };
    let dir = Scratch::new("mtlx-hostile");
    let docs = dir.path("docs");
    std::fs::create_dir_all(&docs).unwrap();
    for kind in ["cycle", "outside", "hostile"] {
        documents(&docs, kind);
    }
    let sky = dir.path("shared/sky.png");
    tool(
        "oiiotool",
        &[
            "--pattern",
            "checker",
            "8x8",
            "3",
            "-d",
            "uint8",
            "-o",
            sky.to_str().unwrap(),
        ],
    );
    let out = dir.path("out");
    let within =
        |doc: &str| asset(&python, &docs.join(doc), &out).run_within(Duration::from_secs(120));
    // An XInclude cycle, an include that is no MaterialX, a corrupt document: clear errors,
    // nothing written.
    let cycle = within("a.mtlx");
    assert!(
        cycle.code == 1 && cycle.stderr.contains("XInclude cycle"),
        "{}",
        cycle.stderr
    );
    let bad = within("not_mtlx.mtlx");
    assert!(
        bad.code == 1
            && bad.stderr.contains("MaterialX cannot read")
            && bad.stderr.contains("XML parse error in /etc/hostname"),
        "{}",
        bad.stderr
    );
    let text = std::fs::read_to_string(docs.join("hostile.mtlx")).unwrap();
    std::fs::write(docs.join("corrupt.mtlx"), &text[..text.len() / 2]).unwrap();
    let corrupt = within("corrupt.mtlx");
    assert!(
        corrupt.code == 1 && corrupt.stderr.contains("XML parse error"),
        "{}",
        corrupt.stderr
    );
    assert!(tree(&out).is_empty(), "{:?}", tree(&out));
    // An include naming a FIFO is refused by kind, never opened.
    for fifo in ["tex/fifo.mtlx", "tex/fifo.png"] {
        assert!(std::process::Command::new("mkfifo")
            .arg(docs.join(fifo))
            .status()
            .unwrap()
            .success());
    }
    let blocked = within("include_fifo.mtlx");
    assert!(
        blocked.code == 1 && blocked.stderr.contains("not a regular file"),
        "{}",
        blocked.stderr
    );
    // An include outside the folder is read (it writes nothing there): its image is converted
    // under DIR/external.
    let outside = within("outside.mtlx");
    assert_eq!(outside.code, 0, "{}", outside.stderr);
    // Images naming a FIFO and /dev/zero fail by kind; `..` out of the folder lands under DIR.
    let hostile = asset(&python, &docs.join("hostile.mtlx"), &out)
        .args(["--json", "-u"])
        .run_within(Duration::from_secs(120));
    assert_eq!(hostile.code, 1, "{}", hostile.stderr);
    let records: Vec<Value> = hostile.stdout.lines().map(json).collect();
    assert_eq!(record(&records, "fifo.png")["status"], "failed");
    assert_eq!(record(&records, "zero")["status"], "failed");
    for (p, _) in tree(&out) {
        assert!(p.starts_with(&out), "{}", p.display());
    }
    assert!(tree(&out)
        .iter()
        .any(|(p, _)| p.starts_with(out.join("external"))));
    // The document itself a FIFO: refused before MaterialX could block on it.
    let doc_fifo = docs.join("fifo_doc.mtlx");
    std::process::Command::new("mkfifo")
        .arg(&doc_fifo)
        .status()
        .unwrap();
    asset(&python, &doc_fifo, &out).fails(2, &["not a regular file"]);
}

#[test]
fn ten_thousand_materialx_nodes_are_read_in_bounded_time() {
    let Some(python) = mtlx() else { return };
    let dir = Scratch::new("mtlx-many");
    documents(&dir.0, "many");
    let run = asset(&python, &dir.path("many.mtlx"), &dir.path("out"))
        .args(["--dry-run", "--json"])
        .run_within(Duration::from_secs(300));
    assert!(run.code == 0, "{}", &run.stderr);
    let decisions: Vec<Value> = run.stdout.lines().map(json).collect();
    assert_eq!(decisions.len(), 1);
    assert_eq!(decisions[0]["uses"].as_array().unwrap().len(), 2500);
}

#[test]
fn without_materialx_the_error_says_what_to_install() {
    let dir = Scratch::new("mtlx-none");
    let doc = dir.write(
        "d.mtlx",
        "<?xml version=\"1.0\"?>\n<materialx version=\"1.39\"/>\n",
    );
    // A MaterialX package that cannot be imported, found before any installed one.
    std::fs::create_dir_all(dir.path("fake/MaterialX")).unwrap();
    dir.write(
        "fake/MaterialX/__init__.py",
        "raise ImportError('no MaterialX here')\n",
    );
    let run = Cmd::new([
        "asset",
        doc.to_str().unwrap(),
        "-o",
        dir.path("out").to_str().unwrap(),
    ])
    .env("PYTHONPATH", dir.path("fake"))
    .env("SPECCONV_USD_PYTHON", python());
    run.fails(
        1,
        &["has no MaterialX", "d.mtlx", "-m pip install MaterialX"],
    );
    assert!(!dir.path("out/d_spectral.mtlx").exists());
}

#[test]
fn farm_submit_refuses_a_materialx_document_and_names_the_command() {
    let dir = Scratch::new("mtlx-farm");
    let doc = dir.write(
        "d.mtlx",
        "<?xml version=\"1.0\"?>\n<materialx version=\"1.39\"/>\n",
    );
    let out = dir.path("out");
    Cmd::new([
        "farm",
        "submit",
        doc.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ])
    .args(["--tasks", "2"])
    .fails(2, &["is a MaterialX document", "specconv asset"]);
    assert!(!out.exists());
}

/// Issue 57, item 5 in a MaterialX document: a raw normal map reaching `normal` through a
/// chain of 70 `dot` nodes (past what the reader follows) is not taken for colour: the walk
/// says it gave up, the texture is not converted (exit 1), and the colour texture beside it is.
#[test]
fn a_materialx_walk_that_gives_up_decides_nothing() {
    let Some(python) = mtlx() else { return };
    let dir = Scratch::new("mtlx-deep");
    documents(&dir.0, "brick");
    let mut chain = String::new();
    let mut previous = "normal_map".to_string();
    for k in 0..70 {
        chain += &format!(
            "    <dot name=\"pass{k}\" type=\"vector3\">\n      \
             <input name=\"in\" type=\"vector3\" nodename=\"{previous}\" />\n    </dot>\n"
        );
        previous = format!("pass{k}");
    }
    let text = format!(
        "<?xml version=\"1.0\"?>\n<materialx version=\"1.38\">\n  \
         <nodegraph name=\"NG\">\n    \
         <image name=\"albedo\" type=\"color3\">\n      \
         <input name=\"file\" type=\"filename\" value=\"tex/brick_color.png\" \
         colorspace=\"srgb_texture\" />\n    </image>\n    \
         <image name=\"normal_map\" type=\"vector3\">\n      \
         <input name=\"file\" type=\"filename\" value=\"tex/brick_normal.png\" />\n    \
         </image>\n{chain}    \
         <output name=\"base\" type=\"color3\" nodename=\"albedo\" />\n    \
         <output name=\"normal\" type=\"vector3\" nodename=\"{previous}\" />\n  \
         </nodegraph>\n  <standard_surface name=\"SS\" type=\"surfaceshader\">\n    \
         <input name=\"base_color\" type=\"color3\" nodegraph=\"NG\" output=\"base\" />\n    \
         <input name=\"normal\" type=\"vector3\" nodegraph=\"NG\" output=\"normal\" />\n  \
         </standard_surface>\n  <surfacematerial name=\"M\" type=\"material\">\n    \
         <input name=\"surfaceshader\" type=\"surfaceshader\" nodename=\"SS\" />\n  \
         </surfacematerial>\n</materialx>\n"
    );
    std::fs::write(dir.path("deep.mtlx"), text).unwrap();
    let out = dir.path("out");
    let run = asset(&python, &dir.path("deep.mtlx"), &out)
        .arg("--json")
        .run();
    assert_eq!(run.code, 1, "{}", run.stderr);
    let records = run.json_lines();
    let normal = record(&records, "brick_normal.png");
    assert_eq!(normal["asset"]["rule"], "undecided", "{normal:#}");
    let why = normal["asset"]["why"].as_str().unwrap();
    assert!(why.contains("gave up"), "{why}");
    assert!(!out.join("tex/brick_normal_spectral.exr").exists());
    assert_eq!(record(&records, "brick_color.png")["status"], "ok");
}

/// Issue 56, item 4: a `.mtlx` inside a usdz (once "No such file or directory") and textures
/// named with `<UVTILE>`: refused, each with a message that names the construct, exit 1,
/// nothing converted.
#[test]
fn constructs_it_does_not_read_are_named() {
    let Some(python) = mtlx() else { return };
    let dir = Scratch::new("mtlx-unread");
    documents(&dir.0, "packaged");
    let out = dir.path("out");
    let run = asset(&python, &dir.path("packed.usdz"), &out).run();
    run.one_error_line(1, &["brick.mtlx", "inside the usdz", "unpack"]);
    assert!(!out.join("tex").exists());
    // <UVTILE> in a MaterialX document's filename.
    let doc = std::fs::read_to_string(dir.path("brick.mtlx")).unwrap();
    assert!(doc.contains("brick_color.png"), "{doc}");
    dir.write(
        "uv.mtlx",
        &doc.replace("brick_color.png", "brick_color.<UVTILE>.png"),
    );
    let run = asset(&python, &dir.path("uv.mtlx"), &dir.path("out2")).run();
    assert_eq!(run.code, 1, "{}", run.stderr);
    assert!(
        run.stderr.contains("<UVTILE>") && run.stderr.contains("<UDIM>"),
        "{}",
        run.stderr
    );
    assert!(!dir.path("out2/tex/brick_color_spectral.exr").exists());
}

/// Issue 56, item 2: a document with a material per MaterialX shading model (standard_surface,
/// open_pbr_surface, gltf_pbr) and colour, data, alpha, bump and subsurface images. Each
/// image's decision is the role tests/asset_mtlx.py checked against the shader's nodedef
/// (MaterialX's standard library, read there on its own), and the copy points exactly the
/// colour images at spectral files, the data images at their originals.
#[test]
fn every_materialx_model_s_images_take_the_role_of_their_input_s_type() {
    let Some(python) = mtlx() else { return };
    let dir = Scratch::new("mtlx-models");
    script("asset_mtlx.py", ["models", dir.0.to_str().unwrap()]);
    let roles = roles_with_textures(&dir, "models.json");
    let out = dir.path("out");
    let records = asset(&python, &dir.path("models.mtlx"), &out)
        .args(["--json"])
        .ok()
        .json_lines();
    let decided: std::collections::BTreeMap<String, String> = records
        .iter()
        .map(|r| {
            let file = Path::new(r["asset"]["texture"].as_str().unwrap());
            let stem = file.file_stem().unwrap().to_string_lossy().into_owned();
            (
                stem,
                r["asset"]["decision"]["kind"].as_str().unwrap().to_owned(),
            )
        })
        .collect();
    assert_eq!(decided, roles, "{records:#?}");
    let copy = copy_files(&python, &out.join("models_spectral.mtlx"));
    assert_eq!(copy["valid"], true, "{copy:#}");
    let files = copy["files"].as_object().unwrap();
    // ss_base also feeds subsurface_radius (data): the copy adds img_ss_base_original, which
    // keeps the original file, for that input.
    assert_eq!(files.len(), roles.len() + 1, "{copy:#}");
    for (node, f) in files {
        let stem = node.trim_start_matches("img_");
        let (stem, kept) = match stem.strip_suffix("_original") {
            Some(s) => (s, true),
            None => (stem, false),
        };
        let want = match roles[stem].as_str() {
            "colour" if !kept => format!("./tex/{stem}_spectral.exr"),
            _ => dir.path(&format!("tex/{stem}.png")).display().to_string(),
        };
        assert_eq!(f["file"], want.as_str(), "{node}: {f}");
        assert_eq!(f["exists"], true, "{node}: {f}");
    }
    let code = "import sys\nimport MaterialX as mx\nd = mx.createDocument()\n\
                mx.readFromXmlFile(d, sys.argv[1])\nsr = d.getNode('SR_M_ss')\n\
                for n in ('base_color', 'subsurface_radius'):\n\
                \x20   print(n, sr.getInput(n).getNodeName())\n";
    let got = std::process::Command::new(&python)
        .args([
            "-c",
            code,
            out.join("models_spectral.mtlx").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(
        String::from_utf8_lossy(&got.stdout),
        "base_color img_ss_base\nsubsurface_radius img_ss_base_original\n",
        "{}",
        String::from_utf8_lossy(&got.stderr)
    );
}
