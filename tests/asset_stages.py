"""Builds the test stages of tests/it/asset.rs with Pixar's usd-core (docs/assets.md):
python3 tests/asset_stages.py KIND DIR. Textures are written by oiiotool beforehand (the test)
or named here without files (the missing ones)."""
import json
import os
import sys
import zipfile

from pxr import Sdf, Usd, UsdGeom, UsdShade, UsdUtils


def material(stage, path, textures):
    """A UsdPreviewSurface material at `path` reading `textures`: (name, file, {output: input},
    sourceColorSpace or None, MaterialX colorspace or None, node id)."""
    mat = UsdShade.Material.Define(stage, path)
    surf = UsdShade.Shader.Define(stage, path + "/Surface")
    surf.CreateIdAttr("UsdPreviewSurface")
    mat.CreateSurfaceOutput().ConnectToSource(surf.ConnectableAPI(), "surface")
    for name, file, feeds, scs, mtlx, sid in textures:
        tex = UsdShade.Shader.Define(stage, path + "/" + name)
        tex.CreateIdAttr(sid or "UsdUVTexture")
        f = tex.CreateInput("file", Sdf.ValueTypeNames.Asset)
        f.Set(file)
        if mtlx:
            f.GetAttr().SetColorSpace(mtlx)
        if scs:
            tex.CreateInput("sourceColorSpace", Sdf.ValueTypeNames.Token).Set(scs)
        for output, inp in feeds.items():
            kind = Sdf.ValueTypeNames.Float if len(output) == 1 else Sdf.ValueTypeNames.Float3
            out = tex.CreateOutput(output, kind)
            if inp == "normal-through":
                # A node between (MaterialX's normalmap): the use ends at its consumer.
                nm = UsdShade.Shader.Define(stage, path + "/NormalMap")
                nm.CreateIdAttr("ND_normalmap")
                nm.CreateInput("in", Sdf.ValueTypeNames.Float3).ConnectToSource(out)
                nout = nm.CreateOutput("out", Sdf.ValueTypeNames.Float3)
                surf.CreateInput("normal", Sdf.ValueTypeNames.Normal3f).ConnectToSource(nout)
            else:
                surf.CreateInput(inp, kind).ConnectToSource(out)
    return mat


def bind(stage, prim_path, mat):
    mesh = UsdGeom.Mesh.Define(stage, prim_path)
    UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(mat)


def T(name, file, feeds, scs=None, mtlx=None, sid=None):
    return (name, file, feeds, scs, mtlx, sid)


def basic(d):
    """Every row of the rules: references, a variant, ARM, alpha, MaterialX colorspace,
    textures outside the folder, UDIM."""
    # The asset, referenced by the shot.
    asset = Usd.Stage.CreateNew(os.path.join(d, "asset.usda"))
    UsdGeom.Xform.Define(asset, "/Asset")
    asset.SetDefaultPrim(asset.GetPrimAtPath("/Asset"))
    m = material(asset, "/Asset/Looks/Rock", [
        T("Albedo", "./tex/rock_albedo.png", {"rgb": "diffuseColor", "a": "opacity"}, "sRGB"),
        T("Arm", "./tex/rock_arm.png", {"r": "occlusion", "g": "roughness", "b": "metallic"}),
        T("Normal", "./tex/rock_normal.png", {"rgb": "normal"}, "raw"),
    ])
    bind(asset, "/Asset/Geo", m)
    vs = asset.GetPrimAtPath("/Asset").GetVariantSets().AddVariantSet("look")
    for look, albedo in (("clean", "./tex/clean_albedo.png"), ("dirty", "./tex/dirty_albedo.png")):
        vs.AddVariant(look)
        vs.SetVariantSelection(look)
        with vs.GetVariantEditContext():
            mv = material(asset, "/Asset/Looks/Variant", [
                T("Albedo", albedo, {"rgb": "diffuseColor"}, "auto")])
            bind(asset, "/Asset/VariantGeo", mv)
    vs.SetVariantSelection("dirty")
    asset.Save()
    shot = Usd.Stage.CreateNew(os.path.join(d, "shot.usda"))
    root = UsdGeom.Xform.Define(shot, "/World")
    shot.SetDefaultPrim(root.GetPrim())
    UsdGeom.Xform.Define(shot, "/World/Rock").GetPrim().GetReferences().AddReference("./asset.usda")
    mx = material(shot, "/World/Looks/Mx", [
        T("Base", "./tex/wood_acescg.exr", {"out": "diffuseColor"}, None, "acescg",
          "ND_image_color3"),
        T("Wood", "./tex/wood.<UDIM>.png", {"rgb": "emissiveColor"}, "sRGB"),
        T("Outside", "../outside/sky.png", {"rgb": "specularColor"}, "sRGB"),
    ])
    bind(shot, "/World/Board", mx)
    unbound = material(shot, "/World/Looks/Unbound", [
        T("Never", "./tex/never.png", {"rgb": "diffuseColor"}, "sRGB")])
    shot.Save()


def conflict(d):
    """One texture node outside both materials (no render context reaches it) whose rgb feeds
    /Looks/A's diffuseColor and /Looks/B's normal: the data use cannot keep the original file
    beside the spectral one."""
    s = Usd.Stage.CreateNew(os.path.join(d, "conflict.usda"))
    tex = UsdShade.Shader.Define(s, "/Textures/Tex")
    tex.CreateIdAttr("UsdUVTexture")
    tex.CreateInput("file", Sdf.ValueTypeNames.Asset).Set("./tex/shared.png")
    rgb = tex.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
    for name, inp, kind in (("A", "diffuseColor", Sdf.ValueTypeNames.Color3f),
                            ("B", "normal", Sdf.ValueTypeNames.Normal3f)):
        m = material(s, "/Looks/" + name, [])
        surf = UsdShade.Shader(s.GetPrimAtPath("/Looks/%s/Surface" % name))
        surf.CreateInput(inp, kind).ConnectToSource(rgb)
        bind(s, "/Geo" + name, m)
    s.Save()


def shared(d):
    """One file read by two texture nodes, each in its material: as /Looks/A's diffuseColor,
    as /Looks/B's normal (the data use keeps the original file: /Looks/B is not touched)."""
    s = Usd.Stage.CreateNew(os.path.join(d, "shared.usda"))
    a = material(s, "/Looks/A", [T("Tex", "./tex/shared.png", {"rgb": "diffuseColor"}, "sRGB")])
    b = material(s, "/Looks/B", [T("Tex", "./tex/shared.png", {"rgb": "normal"}, "raw")])
    bind(s, "/GeoA", a)
    bind(s, "/GeoB", b)
    s.Save()


def mixed(d):
    """One colour texture and one data texture."""
    s = Usd.Stage.CreateNew(os.path.join(d, "mixed.usda"))
    m = material(s, "/Looks/M", [
        T("Albedo", "./tex/rock_albedo.png", {"rgb": "diffuseColor"}, "sRGB"),
        T("Arm", "./tex/rock_arm.png", {"g": "roughness", "b": "metallic"}),
    ])
    bind(s, "/Geo", m)
    s.Save()


def grey(d):
    """Two grey (one-channel) textures: one feeds diffuseColor with no space named, one feeds
    roughness."""
    s = Usd.Stage.CreateNew(os.path.join(d, "grey.usda"))
    m = material(s, "/Looks/G", [
        T("Albedo", "./tex/grey_albedo.png", {"rgb": "diffuseColor"}),
        T("Rough", "./tex/grey_rough.png", {"r": "roughness"}),
    ])
    bind(s, "/Geo", m)
    s.Save()


def missing(d):
    s = Usd.Stage.CreateNew(os.path.join(d, "missing.usda"))
    m = material(s, "/Looks/M", [T("Gone", "./tex/gone.png", {"rgb": "diffuseColor"}, "sRGB")])
    bind(s, "/Geo", m)
    s.Save()


def cycle(d):
    a = Sdf.Layer.CreateNew(os.path.join(d, "cycle_a.usda"))
    b = Sdf.Layer.CreateNew(os.path.join(d, "cycle_b.usda"))
    for layer, other in ((a, "./cycle_b.usda"), (b, "./cycle_a.usda")):
        prim = Sdf.CreatePrimInLayer(layer, "/Root")
        prim.specifier = Sdf.SpecifierDef
        prim.referenceList.Prepend(Sdf.Reference(other, "/Root"))
        layer.defaultPrim = "Root"
        layer.Save()


def package(d):
    """A usdz holding its stage and texture (tex/rock_albedo.png must exist)."""
    s = Usd.Stage.CreateNew(os.path.join(d, "packed.usdc"))
    m = material(s, "/Looks/P", [
        T("Albedo", "tex/rock_albedo.png", {"rgb": "diffuseColor"}, "sRGB")])
    bind(s, "/Geo", m)
    s.Save()
    cwd = os.getcwd()
    os.chdir(d)
    try:
        UsdUtils.CreateNewUsdzPackage("packed.usdc", "packed.usdz")
    finally:
        os.chdir(cwd)


def escape_package(d):
    """Issue 57, item 4: a usdz holding two different pictures as `escape.png` and
    `../escape.png` (tex/rock_albedo.png and tex/rock_normal.png; both must exist), each read
    as colour by its own material."""
    s = Usd.Stage.CreateNew(os.path.join(d, "escape.usdc"))
    for path, file in (("/Looks/In", "./escape.png"), ("/Looks/Up", "../escape.png")):
        m = material(s, path, [T("Albedo", file, {"rgb": "diffuseColor"}, "sRGB")])
        bind(s, "/Geo" + path.rsplit("/", 1)[1], m)
    s.Save()
    w = Sdf.ZipFileWriter.CreateNew(os.path.join(d, "escape.usdz"))
    w.AddFile(os.path.join(d, "escape.usdc"), "escape.usdc")
    w.AddFile(os.path.join(d, "tex", "rock_albedo.png"), "escape.png")
    w.AddFile(os.path.join(d, "tex", "rock_normal.png"), "../escape.png")
    w.Save()


def stem_clash(d):
    """Issue 57, item 11: tex/a.png, tex/a.tif and tex/a_png.png (made by the caller), each
    read as colour: by stem and extension two outputs meet (a_png_spectral.exr)."""
    s = Usd.Stage.CreateNew(os.path.join(d, "stem_clash.usda"))
    for k, file in enumerate(("./tex/a.png", "./tex/a.tif", "./tex/a_png.png")):
        m = material(s, "/Looks/M%d" % k, [T("Albedo", file, {"rgb": "diffuseColor"}, "sRGB")])
        bind(s, "/Geo%d" % k, m)
    s.Save()


def self_sublayer(d):
    """Issue 57, item 2: a stage that sublayers the layer `asset -o .` would write
    (self_sublayer_spectral.usda, with an opinion of its own)."""
    own = Sdf.Layer.CreateNew(os.path.join(d, "self_sublayer_spectral.usda"))
    prim = Sdf.CreatePrimInLayer(own, "/Notes")
    prim.specifier = Sdf.SpecifierDef
    own.Save()
    s = Usd.Stage.CreateNew(os.path.join(d, "self_sublayer.usda"))
    m = material(s, "/Looks/A", [T("Albedo", "./tex/rock_albedo.png", {"rgb": "diffuseColor"},
                                   "sRGB")])
    bind(s, "/Geo", m)
    s.GetRootLayer().subLayerPaths.append("./self_sublayer_spectral.usda")
    s.Save()


def foreign(d):
    """Issue 56, item 2: an Arnold network (`arnold:image` feeding `arnold:standard_surface`
    through the material's `outputs:arnold:surface`), a RenderMan one (`PxrTexture` feeding
    `PxrSurface` through `outputs:ri:surface`), and a studio's own shaders no definition
    specconv knows has (`studio:projector` feeding `studio:surface`), each reading a file,
    bound to meshes."""
    s = Usd.Stage.CreateNew(os.path.join(d, "foreign.usda"))
    for path, context, surface, image, out_name, file in (
            ("/Looks/Ai", "arnold", "arnold:standard_surface", "arnold:image", "rgba",
             "./tex/rock_albedo.png"),
            ("/Looks/Ri", "ri", "PxrSurface", "PxrTexture", "resultRGB",
             "./tex/dirty_albedo.png"),
            ("/Looks/Studio", "", "studio:surface", "studio:projector", "rgb",
             "./tex/clean_albedo.png")):
        m = UsdShade.Material.Define(s, path)
        surf = UsdShade.Shader.Define(s, path + "/Surface")
        surf.CreateIdAttr(surface)
        m.CreateSurfaceOutput(context).ConnectToSource(surf.ConnectableAPI(), "out")
        tex = UsdShade.Shader.Define(s, path + "/Image")
        tex.CreateIdAttr(image)
        tex.CreateInput("filename", Sdf.ValueTypeNames.Asset).Set(file)
        o = tex.CreateOutput(out_name, Sdf.ValueTypeNames.Color3f)
        name = {"arnold": "base_color", "ri": "diffuseColor"}.get(context, "tint")
        surf.CreateInput(name, Sdf.ValueTypeNames.Color3f).ConnectToSource(o)
        bind(s, "/Geo" + path.rsplit("/", 1)[1], m)
    s.Save()


def mtlx_context(d):
    """Issue 56, item 1: a MaterialX-in-USD material with no universal terminal, only
    `outputs:mtlx:surface` (ND_standard_surface_surfaceshader reading an ND_image_color3)."""
    s = Usd.Stage.CreateNew(os.path.join(d, "mtlx_context.usda"))
    m = UsdShade.Material.Define(s, "/Looks/M")
    surf = UsdShade.Shader.Define(s, "/Looks/M/Surface")
    surf.CreateIdAttr("ND_standard_surface_surfaceshader")
    m.CreateSurfaceOutput("mtlx").ConnectToSource(surf.ConnectableAPI(), "out")
    img = UsdShade.Shader.Define(s, "/Looks/M/Image")
    img.CreateIdAttr("ND_image_color3")
    f = img.CreateInput("file", Sdf.ValueTypeNames.Asset)
    f.Set("./tex/rock_albedo.png")
    f.GetAttr().SetColorSpace("srgb_texture")
    o = img.CreateOutput("out", Sdf.ValueTypeNames.Color3f)
    surf.CreateInput("base_color", Sdf.ValueTypeNames.Color3f).ConnectToSource(o)
    bind(s, "/Geo", m)
    s.Save()


def udim_conflict(d):
    """Issue 57, item 6: a UDIM pattern read as colour whose tile 1001 is read by its own
    name as a normal map."""
    s = Usd.Stage.CreateNew(os.path.join(d, "udim_conflict.usda"))
    a = material(s, "/Looks/A", [T("Tex", "./tex/wood.<UDIM>.png", {"rgb": "diffuseColor"})])
    b = material(s, "/Looks/B", [T("Tex", "./tex/wood.1001.png", {"rgb": "normal"}, "raw")])
    bind(s, "/GeoA", a)
    bind(s, "/GeoB", b)
    s.Save()


def deep(d, n=70):
    """Issue 57, item 5: a normal map (tex/rock_normal.png, no sourceColorSpace) reaching
    inputs:normal through `n` pass-through nodes, more than the reader follows; and a colour
    texture read directly beside it."""
    s = Usd.Stage.CreateNew(os.path.join(d, "deep.usda"))
    m = material(s, "/Looks/Deep", [
        T("Albedo", "./tex/rock_albedo.png", {"rgb": "diffuseColor"}, "sRGB")])
    tex = UsdShade.Shader.Define(s, "/Looks/Deep/Normal")
    tex.CreateIdAttr("UsdUVTexture")
    tex.CreateInput("file", Sdf.ValueTypeNames.Asset).Set("./tex/rock_normal.png")
    out = tex.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
    for k in range(n):
        step = UsdShade.Shader.Define(s, "/Looks/Deep/Pass%03d" % k)
        step.CreateIdAttr("ND_dot_vector3")
        step.CreateInput("in", Sdf.ValueTypeNames.Float3).ConnectToSource(out)
        out = step.CreateOutput("out", Sdf.ValueTypeNames.Float3)
    surf = UsdShade.Shader(s.GetPrimAtPath("/Looks/Deep/Surface"))
    surf.CreateInput("normal", Sdf.ValueTypeNames.Normal3f).ConnectToSource(out)
    bind(s, "/Geo", m)
    s.Save()


def many(d, n=10000):
    s = Usd.Stage.CreateNew(os.path.join(d, "many.usda"))
    m = material(s, "/Looks/M", [T("Tex", "./tex/rock_albedo.png", {"rgb": "diffuseColor"}, "sRGB")])
    for i in range(n):
        bind(s, "/World/G%d" % i, m)
    s.Save()


def hostile(d):
    """Texture paths naming a FIFO, /dev/zero, and `..` out of the folder."""
    s = Usd.Stage.CreateNew(os.path.join(d, "hostile.usda"))
    m = material(s, "/Looks/H", [
        T("Fifo", "./tex/fifo.png", {"rgb": "diffuseColor"}, "sRGB"),
        T("Zero", "/dev/zero", {"rgb": "emissiveColor"}, "sRGB"),
        T("Up", "../../../../../../../../../../etc/hostname", {"rgb": "specularColor"}, "sRGB"),
    ])
    bind(s, "/Geo", m)
    s.Save()


# Issue 56, item 2: one material per shading model, each texture its own file, and the role
# each should get. A role is checked here against the type the input has in the definition
# (MaterialX's nodedef, usd-core's Sdr; for Arnold and RenderMan, whose definitions ship
# only with the renderers, the USD type their own writers give the input: arnold-usd writes
# RGB as color3f, VECTOR as vector3f, and hdPrman's stages type PxrSurface's colours
# color3f). A colour type is colour but for the inputs that hold a quantity per channel
# (PER_CHANNEL: a radius or mean free path, an index, an extinction, an opacity).
PER_CHANNEL = {("ND_standard_surface_surfaceshader", "subsurface_radius"),
               ("ND_standard_surface_surfaceshader", "opacity"),
               ("ND_open_pbr_surface_surfaceshader", "subsurface_radius_scale"),
               ("arnold:standard_surface", "subsurface_radius"),
               ("PxrSurface", "subsurfaceDmfpColor")}
# (material, surface id, terminal context, surface output, [(texture id, file input (and its
# USD type), file, output (and its USD type), [nodes between: (id, in, out)], surface input,
# its USD type, role)]). Roles: colour, data, alpha (the colour texture's own alpha).
F3, C3, C4, FL, V3, N3 = "float3", "color3f", "color4f", "float", "vector3f", "normal3f"
NETWORKS = [
    ("Preview", "UsdPreviewSurface", "", "surface", [
        ("UsdUVTexture", ("file", "asset"), "up_base", ("rgb", F3), [], "diffuseColor", C3,
         "colour"),
        ("UsdUVTexture", ("file", "asset"), "up_base", ("a", FL), [], "opacity", FL, "alpha"),
        ("UsdUVTexture", ("file", "asset"), "up_rough", ("r", FL), [], "roughness", FL, "data"),
        ("UsdUVTexture", ("file", "asset"), "up_normal", ("rgb", F3), [], "normal", N3, "data"),
    ]),
    ("Standard", "ND_standard_surface_surfaceshader", "mtlx", "out", [
        ("ND_image_color3", ("file", "asset"), "ss_base", ("out", C3), [], "base_color", C3,
         "colour"),
        ("ND_image_color3", ("file", "asset"), "ss_sss", ("out", C3), [], "subsurface_color", C3,
         "colour"),
        ("ND_image_color3", ("file", "asset"), "ss_radius", ("out", C3), [], "subsurface_radius",
         C3, "data"),
        ("ND_image_color3", ("file", "asset"), "ss_opacity", ("out", C3), [], "opacity", C3,
         "data"),
        ("ND_image_vector3", ("file", "asset"), "ss_normal", ("out", V3),
         [("ND_normalmap_float", "in", "out")], "normal", V3, "data"),
        ("ND_image_float", ("file", "asset"), "ss_rough", ("out", FL), [], "specular_roughness",
         FL, "data"),
    ]),
    # OpenChessSet's pieces: the base colour image feeds subsurface_radius too.
    ("Chess", "ND_standard_surface_surfaceshader", "mtlx", "out", [
        ("ND_image_color3", ("file", "asset"), "ch_base", ("out", C3), [], "base_color", C3,
         "colour"),
        ("ND_image_color3", ("file", "asset"), "ch_base", ("out", C3), [], "subsurface_radius",
         C3, "data"),
    ]),
    ("OpenPbr", "ND_open_pbr_surface_surfaceshader", "mtlx", "out", [
        ("ND_image_color3", ("file", "asset"), "op_base", ("out", C3), [], "base_color", C3,
         "colour"),
        ("ND_image_color3", ("file", "asset"), "op_scale", ("out", C3), [],
         "subsurface_radius_scale", C3, "data"),
        ("ND_image_float", ("file", "asset"), "op_weight", ("out", FL), [], "subsurface_weight",
         FL, "data"),
    ]),
    ("Gltf", "ND_gltf_pbr_surfaceshader", "mtlx", "out", [
        ("ND_gltf_colorimage", ("file", "asset"), "gl_base", ("outcolor", C3), [], "base_color",
         C3, "colour"),
        ("ND_gltf_colorimage", ("file", "asset"), "gl_base", ("outa", FL), [], "alpha", FL,
         "alpha"),
        ("ND_gltf_image_float_float_1_0", ("file", "asset"), "gl_rough", ("out", FL), [], "roughness", FL,
         "data"),
    ]),
    ("Arnold", "arnold:standard_surface", "arnold", "out", [
        ("arnold:image", ("filename", "asset"), "ai_base", ("out", C4), [], "base_color", C3,
         "colour"),
        ("arnold:image", ("filename", "asset"), "ai_base", ("a", FL), [], "opacity", C3, "alpha"),
        ("arnold:image", ("filename", "string"), "ai_radius", ("out", C4), [],
         "subsurface_radius", C3, "data"),
        ("arnold:image", ("filename", "string"), "ai_rough", ("r", FL), [], "specular_roughness",
         FL, "data"),
        ("arnold:image", ("filename", "asset"), "ai_normal", ("out", C4),
         [("arnold:normal_map", "input", "out")], "normal", V3, "data"),
        ("arnold:image", ("filename", "asset"), "ai_bump", ("r", FL),
         [("arnold:bump2d", "bump_map", "out")], "coat_normal", V3, "data"),
    ]),
    ("RenderMan", "PxrSurface", "ri", "out", [
        ("PxrTexture", ("filename", "asset"), "ri_base", ("resultRGB", C3), [], "diffuseColor",
         C3, "colour"),
        ("PxrTexture", ("filename", "asset"), "ri_base", ("resultA", FL), [], "presence", FL,
         "alpha"),
        ("PxrTexture", ("filename", "token"), "ri_dmfp", ("resultRGB", C3), [],
         "subsurfaceDmfpColor", C3, "data"),
        ("PxrTexture", ("filename", "asset"), "ri_rough", ("resultR", FL), [],
         "specularRoughness", FL, "data"),
        ("PxrNormalMap", ("filename", "asset"), "ri_normal", ("resultN", N3), [], "bumpNormal",
         N3, "data"),
        ("PxrBump", ("filename", "asset"), "ri_bump", ("resultN", N3), [],
         "specularBumpNormal", N3, "data"),
        ("PxrMultiTexture", ("filename0", "asset"), "ri_multi0", ("resultRGB", C3), [],
         "subsurfaceColor", C3, "colour"),
        ("PxrMultiTexture", ("filename1", "asset"), "ri_multi1", ("resultRGB", C3), [],
         "subsurfaceColor", C3, "colour"),
    ]),
]


# The space a reader's own input declares: PxrTexture's `linearize` 1 (the reverse sRGB
# transform) and Arnold's image `color_space`, each the library's `source-color-space` or
# `materialx-colorspace` rule (the rule the test expects, then the input).
DECLARED = {
    "ri_base": {"source-color-space": ("linearize", "int", 1)},
    "ai_base": {"materialx-colorspace": ("color_space", "string", "sRGB - Texture")},
}


def definition_type(surface, name):
    """The input's type in the definition the issue names, read here on its own: MaterialX's
    nodedef, usd-core's Sdr; None for Arnold and RenderMan (no definition ships)."""
    if surface.startswith("ND_"):
        import MaterialX as mx
        lib = mx.createDocument()
        mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
        return lib.getNodeDef(surface).getActiveInput(name).getType()
    if surface == "UsdPreviewSurface":
        from pxr import Sdr
        node = Sdr.Registry().GetShaderNodeByIdentifier(surface)
        return str(node.GetShaderInput(name).GetTypeAsSdfType().GetSdfType())
    return None


def expected_role(surface, name, usd_type, role):
    """The fixture's role, checked against the definition's type (else the USD type the
    renderer's writer gives the input)."""
    t = definition_type(surface, name) or usd_type
    colour = t in ("color3", "color4", "color3f", "color4f") and \
        (surface, name) not in PER_CHANNEL
    assert role == "alpha" or (role == "colour") == colour, (surface, name, t, role)
    return role


def networks(d):
    """Every shading model's network in one stage: colour, data, alpha, normal, bump and
    subsurface textures (NETWORKS); writes networks.json, {file: role}, the roles checked
    against the definitions, and the files for the caller to make."""
    s = Usd.Stage.CreateNew(os.path.join(d, "networks.usda"))
    roles = {}
    for name, surface, context, out, textures in NETWORKS:
        path = "/Looks/" + name
        m = UsdShade.Material.Define(s, path)
        surf = UsdShade.Shader.Define(s, path + "/Surface")
        surf.CreateIdAttr(surface)
        m.CreateSurfaceOutput(context).ConnectToSource(surf.ConnectableAPI(), out)
        for k, (tid, (file_in, file_type), file, (o, o_type), between, inp, inp_type,
                role) in enumerate(textures):
            # One node for the files of a multi-file reader (ri_multi0, ri_multi1).
            tex_path = "%s/T_%s" % (path, file.rstrip("0123456789"))
            tex = UsdShade.Shader(s.GetPrimAtPath(tex_path)) if s.GetPrimAtPath(tex_path) \
                else UsdShade.Shader.Define(s, tex_path)
            tex.CreateIdAttr(tid)
            value = "./tex/%s.png" % file
            f = tex.CreateInput(file_in, Sdf.ValueTypeNames.Find(file_type))
            f.Set(Sdf.AssetPath(value) if file_type == "asset" else value)
            source = tex.CreateOutput(o, Sdf.ValueTypeNames.Find(o_type))
            for declared, (input_name, type_name, v) in DECLARED.get(file, {}).items():
                tex.CreateInput(input_name, Sdf.ValueTypeNames.Find(type_name)).Set(v)
            for j, (bid, b_in, b_out) in enumerate(between):
                b = UsdShade.Shader.Define(s, "%s/Between%d_%d" % (path, k, j))
                b.CreateIdAttr(bid)
                b.CreateInput(b_in, Sdf.ValueTypeNames.Find(o_type)).ConnectToSource(source)
                source = b.CreateOutput(b_out, Sdf.ValueTypeNames.Find(inp_type))
            surf.CreateInput(inp, Sdf.ValueTypeNames.Find(inp_type)).ConnectToSource(source)
            got = expected_role(surface, inp, inp_type, role)
            if got != "alpha":
                # A file with a colour use is colour; its data uses keep the original.
                roles[file] = "colour" if "colour" in (roles.get(file), got) else got
        bind(s, "/Geo/" + name, m)
    s.Save()
    with open(os.path.join(d, "networks.json"), "w") as out_file:
        json.dump(roles, out_file, indent=1, sort_keys=True)
    with open(os.path.join(d, "declared.json"), "w") as out_file:
        json.dump({f: next(iter(r)) for f, r in DECLARED.items()}, out_file, sort_keys=True)


if __name__ == "__main__":
    globals()[sys.argv[1]](sys.argv[2])
