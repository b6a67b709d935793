"""Builds the MaterialX documents (and the USD stages that reference them) of
tests/it/asset_mtlx.rs with the MaterialX package and usd-core (docs/assets.md):
python3 tests/asset_mtlx.py KIND DIR. Textures are written by oiiotool beforehand (the test)
or named here without files (the missing ones)."""
import os
import sys

import MaterialX as mx


LIBRARY = mx.createDocument()
mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), LIBRARY)


def write(doc, path):
    """Writes `doc`, valid against MaterialX's standard library."""
    doc.setDataLibrary(LIBRARY)
    ok, why = doc.validate()
    assert ok, why
    mx.writeToXmlFile(doc, path)


def image(parent, name, file, kind="color3", colorspace=None, category="image"):
    node = parent.addNode(category, name, kind)
    inp = node.addInput("file", "filename")
    inp.setValueString(file)
    if colorspace:
        inp.setColorSpace(colorspace)
    return node


def connect(node, name, kind, source, output=None):
    inp = node.addInput(name, kind)
    inp.setNodeName(source.getName())
    if output:
        inp.setOutputString(output)
    return inp


def material(doc, name, shader):
    mat = doc.addNode("surfacematerial", name, "material")
    connect(mat, "surfaceshader", "surfaceshader", shader)
    return mat


def brick_graph(doc):
    """A node graph: a colour image (its file through the graph's interface, sRGB) whose rgb
    feeds base_color and whose alpha (extract 3, then convert) feeds opacity; an ARM image
    split by separate3 into roughness and metalness; a normal map through normalmap."""
    ng = doc.addNodeGraph("NG_brick")
    iface = ng.addInput("color_file", "filename")
    iface.setValueString("brick_color.png")
    iface.setColorSpace("srgb_texture")
    color = ng.addNode("image", "color", "color4")
    color.addInput("file", "filename").setInterfaceName("color_file")
    alpha = ng.addNode("extract", "alpha", "float")
    connect(alpha, "in", "color4", color)
    alpha.setInputValue("index", 3)
    alpha3 = ng.addNode("convert", "alpha3", "color3")
    connect(alpha3, "in", "float", alpha)
    rgb = ng.addNode("convert", "rgb", "color3")
    connect(rgb, "in", "color4", color)
    arm = image(ng, "arm", "brick_arm.png", "vector3")
    split = ng.addNode("separate3", "arm_split", "multioutput")
    connect(split, "in", "vector3", arm)
    for out in ("outx", "outy", "outz"):
        split.addOutput(out, "float")
    normal = image(ng, "normal", "brick_normal.png", "vector3")
    nmap = ng.addNode("normalmap", "nmap", "vector3")
    connect(nmap, "in", "vector3", normal)
    for out, node, kind, output in (("base_color_out", rgb, "color3", None),
                                    ("opacity_out", alpha3, "color3", None),
                                    ("rough_out", split, "float", "outy"),
                                    ("metal_out", split, "float", "outz"),
                                    ("normal_out", nmap, "vector3", None)):
        o = ng.addOutput(out, kind)
        o.setNodeName(node.getName())
        if output:
            o.setOutputString(output)
    return ng


def brick(d):
    """brick.mtlx: the brick graph behind a standard_surface, a float height image as
    displacement (fileprefix tex/ on the document), and an XInclude (lib/wood.mtlx, its own
    fileprefix) whose material reads a UDIM colour image in ACEScg."""
    os.makedirs(os.path.join(d, "lib"), exist_ok=True)
    lib = mx.createDocument()
    lib.setFilePrefix("tex/")
    wood = image(lib, "wood_color", "wood.<UDIM>.png", "color3", "acescg")
    sr = lib.addNode("standard_surface", "SR_wood", "surfaceshader")
    connect(sr, "base_color", "color3", wood)
    material(lib, "M_wood", sr)
    write(lib, os.path.join(d, "lib", "wood.mtlx"))

    doc = mx.createDocument()
    doc.setColorSpace("lin_rec709")
    doc.setFilePrefix("tex/")
    mx.prependXInclude(doc, "lib/wood.mtlx")
    ng = brick_graph(doc)
    sr = doc.addNode("standard_surface", "SR_brick", "surfaceshader")
    for inp, kind, out in (("base_color", "color3", "base_color_out"),
                           ("opacity", "color3", "opacity_out"),
                           ("specular_roughness", "float", "rough_out"),
                           ("metalness", "float", "metal_out"),
                           ("normal", "vector3", "normal_out")):
        i = sr.addInput(inp, kind)
        i.setNodeGraphString(ng.getName())
        i.setOutputString(out)
    height = image(doc, "height", "brick_height.png", "float")
    disp = doc.addNode("displacement", "disp", "displacementshader")
    connect(disp, "displacement", "float", height)
    mat = material(doc, "M_brick", sr)
    connect(mat, "displacementshader", "displacementshader", disp)
    # A node no material reads: never listed.
    image(doc, "unused", "never.png")
    write(doc, os.path.join(d, "brick.mtlx"))


def conflict(d):
    """One image whose colour feeds base_color in one material and, through an `extract`
    (a node between: the copy cannot give that use the original file), roughness in the
    other; and a missing file, named by its node."""
    doc = mx.createDocument()
    a = image(doc, "shared_colour", "tex/shared.png", "color3", "srgb_texture")
    sa = doc.addNode("standard_surface", "SR_a", "surfaceshader")
    connect(sa, "base_color", "color3", a)
    material(doc, "M_a", sa)
    b = doc.addNode("extract", "shared_red", "float")
    connect(b, "in", "color3", a)
    b.setInputValue("index", 0)
    sb = doc.addNode("standard_surface", "SR_b", "surfaceshader")
    connect(sb, "specular_roughness", "float", b)
    gone = image(doc, "gone", "tex/no_such_file.png", "color3")
    connect(sb, "base_color", "color3", gone)
    material(doc, "M_b", sb)
    write(doc, os.path.join(d, "conflict.mtlx"))


def cycle(d):
    """a.mtlx includes b.mtlx, which includes a.mtlx."""
    for name, other in (("a", "b"), ("b", "a")):
        doc = mx.createDocument()
        mx.prependXInclude(doc, other + ".mtlx")
        image(doc, "img_" + name, "tex/rock_albedo.png")
        write(doc, os.path.join(d, name + ".mtlx"))


def outside(d):
    """A document whose XInclude is outside its folder (../shared/lib.mtlx, whose image is
    beside it), and one that includes a file that is no MaterialX (/etc/hostname)."""
    shared = os.path.join(os.path.dirname(d.rstrip("/")), "shared")
    os.makedirs(shared, exist_ok=True)
    lib = mx.createDocument()
    img = image(lib, "sky", "../shared/sky.png", "color3", "srgb_texture")
    sr = lib.addNode("standard_surface", "SR_sky", "surfaceshader")
    connect(sr, "emission_color", "color3", img)
    material(lib, "M_sky", sr)
    write(lib, os.path.join(shared, "lib.mtlx"))
    doc = mx.createDocument()
    mx.prependXInclude(doc, "../shared/lib.mtlx")
    write(doc, os.path.join(d, "outside.mtlx"))
    bad = mx.createDocument()
    mx.prependXInclude(bad, "/etc/hostname")
    write(bad, os.path.join(d, "not_mtlx.mtlx"))


def hostile(d):
    """Filenames naming a FIFO, /dev/zero and `..` out of the folder; and a document whose
    XInclude names a FIFO."""
    doc = mx.createDocument()
    sr = doc.addNode("standard_surface", "SR_h", "surfaceshader")
    for name, file, inp in (("fifo", "tex/fifo.png", "base_color"),
                            ("zero", "/dev/zero", "emission_color"),
                            ("up", "../../../../../../../../../../etc/hostname",
                             "specular_color")):
        connect(sr, inp, "color3", image(doc, name, file, "color3", "srgb_texture"))
    material(doc, "M_h", sr)
    write(doc, os.path.join(d, "hostile.mtlx"))
    inc = mx.createDocument()
    mx.prependXInclude(inc, "tex/fifo.mtlx")
    write(inc, os.path.join(d, "include_fifo.mtlx"))


def many(d, n=10000):
    """n nodes: n/4 materials, each a standard_surface reading one image through a multiply,
    all of one file."""
    doc = mx.createDocument()
    for k in range(n // 4):
        img = image(doc, "img%d" % k, "tex/rock_albedo.png", "color3", "srgb_texture")
        mul = doc.addNode("multiply", "mul%d" % k, "color3")
        connect(mul, "in1", "color3", img)
        sr = doc.addNode("standard_surface", "SR%d" % k, "surfaceshader")
        connect(sr, "base_color", "color3", mul)
        material(doc, "M%d" % k, sr)
    write(doc, os.path.join(d, "many.mtlx"))


def stage(d):
    """shot.usda: a prim referencing brick.mtlx's material M_brick, one a UsdPreviewSurface
    material reading tex/rock_albedo.png, and a scope referencing two documents, one of which
    has the M_wood bound below it; each bound to a mesh. brick(d) is built first."""
    from pxr import Sdf, Usd, UsdGeom, UsdShade
    brick(d)
    s = Usd.Stage.CreateNew(os.path.join(d, "shot.usda"))
    m = s.DefinePrim("/World/Looks/Brick", "Material")
    m.GetReferences().AddReference("./brick.mtlx", "/MaterialX/Materials/M_brick")
    mesh = UsdGeom.Mesh.Define(s, "/World/Wall")
    UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(UsdShade.Material(m))
    rock = UsdShade.Material.Define(s, "/World/Looks/Rock")
    surf = UsdShade.Shader.Define(s, "/World/Looks/Rock/Surface")
    surf.CreateIdAttr("UsdPreviewSurface")
    rock.CreateSurfaceOutput().ConnectToSource(surf.ConnectableAPI(), "surface")
    tex = UsdShade.Shader.Define(s, "/World/Looks/Rock/Albedo")
    tex.CreateIdAttr("UsdUVTexture")
    tex.CreateInput("file", Sdf.ValueTypeNames.Asset).Set("./tex/rock_albedo.png")
    out = tex.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
    surf.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(out)
    rockmesh = UsdGeom.Mesh.Define(s, "/World/Rock")
    UsdShade.MaterialBindingAPI.Apply(rockmesh.GetPrim()).Bind(rock)
    # A scope referencing two documents' /MaterialX (usdMtlx's root), a mesh bound to M_wood
    # below it: brick.mtlx has it (through its XInclude), extra.mtlx has not.
    extra = mx.createDocument()
    img = image(extra, "extra_color", "tex/never.png", "color3", "srgb_texture")
    sr = extra.addNode("standard_surface", "SR_extra", "surfaceshader")
    connect(sr, "base_color", "color3", img)
    material(extra, "M_extra", sr)
    write(extra, os.path.join(d, "extra.mtlx"))
    lib = s.DefinePrim("/World/Lib", "Scope")
    lib.GetReferences().AddReference("./extra.mtlx", "/MaterialX")
    lib.GetReferences().AddReference("./brick.mtlx", "/MaterialX")
    floor = UsdGeom.Mesh.Define(s, "/World/Floor")
    UsdShade.MaterialBindingAPI.Apply(floor.GetPrim()).GetDirectBindingRel().SetTargets(
        [Sdf.Path("/World/Lib/Materials/M_wood")])
    s.Save()


def packaged(d):
    """Issue 56, item 4: packed.usdz holding a stage that references brick.mtlx, packaged
    with it (and its textures)."""
    from pxr import Sdf, Usd, UsdGeom, UsdShade
    brick(d)
    s = Usd.Stage.CreateNew(os.path.join(d, "inner.usdc"))
    m = s.DefinePrim("/World/Looks/Brick", "Material")
    m.GetReferences().AddReference("./brick.mtlx", "/MaterialX/Materials/M_brick")
    mesh = UsdGeom.Mesh.Define(s, "/World/Wall")
    UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(UsdShade.Material(m))
    s.Save()
    w = Sdf.ZipFileWriter.CreateNew(os.path.join(d, "packed.usdz"))
    w.AddFile(os.path.join(d, "inner.usdc"), "inner.usdc")
    w.AddFile(os.path.join(d, "brick.mtlx"), "brick.mtlx")
    for name in sorted(os.listdir(os.path.join(d, "tex"))):
        w.AddFile(os.path.join(d, "tex", name), "tex/" + name)
    w.Save()


# Issue 56, item 2: a document with a material per MaterialX shading model; each image its own
# file, with the role it should get: (material, shader category, [(file, image category and
# type, output or None, [nodes between: (category, type, in)], shader input, role)]). The role
# is checked against the shader's nodedef in MaterialX's standard library (a colour type is
# colour but for PER_CHANNEL, colour-typed quantities held per channel).
PER_CHANNEL = {("standard_surface", "subsurface_radius"),
               ("open_pbr_surface", "subsurface_radius_scale")}
MODELS = [
    ("M_ss", "standard_surface", [
        ("ss_base", ("image", "color3"), None, [], "base_color", "colour"),
        # OpenChessSet's pieces: the base colour image feeds subsurface_radius too.
        ("ss_base", ("image", "color3"), None, [], "subsurface_radius", "data"),
        ("ss_bump", ("image", "float"), None, [("bump", "vector3", "height")], "normal", "data"),
    ]),
    ("M_ss2", "standard_surface", [
        ("ss_radius", ("image", "color3"), None, [], "subsurface_radius", "data"),
    ]),
    ("M_op", "open_pbr_surface", [
        ("op_base", ("image", "color3"), None, [], "base_color", "colour"),
        ("op_scale", ("image", "color3"), None, [], "subsurface_radius_scale", "data"),
    ]),
    ("M_gl", "gltf_pbr", [
        ("gl_base", ("gltf_colorimage", "multioutput"), "outcolor", [], "base_color", "colour"),
        ("gl_base", ("gltf_colorimage", "multioutput"), "outa", [], "alpha", "alpha"),
        ("gl_rough", ("image", "float"), None, [], "roughness", "data"),
    ]),
]


def models(d):
    """MODELS as models.mtlx, and models.json ({file: role}) for the test."""
    import json
    doc = mx.createDocument()
    roles = {}
    for name, category, images in MODELS:
        shader = doc.addNode(category, "SR_" + name, "surfaceshader")
        nodedef = LIBRARY.getMatchingNodeDefs(category)[0]
        made = {}
        for k, (file, (img_cat, img_type), output, between, inp, role) in enumerate(images):
            if file not in made:
                node = image(doc, "img_" + file, "tex/%s.png" % file, img_type, category=img_cat)
                if img_type == "multioutput":
                    node.addOutput("outcolor", "color3")
                    node.addOutput("outa", "float")
                made[file] = node
            source, out_type = made[file], img_type if output is None else \
                ("float" if output == "outa" else "color3")
            for j, (b_cat, b_type, b_in) in enumerate(between):
                b = doc.addNode(b_cat, "%s_%d_%d" % (name, k, j), b_type)
                connect(b, b_in, out_type, source, output)
                source, output, out_type = b, None, b_type
            t = nodedef.getActiveInput(inp).getType()
            colour = t in ("color3", "color4") and (category, inp) not in PER_CHANNEL
            assert role == "alpha" or (role == "colour") == colour, (category, inp, t, role)
            connect(shader, inp, t, source, output)
            if role != "alpha":
                # A file with a colour use is colour; its data uses keep the original.
                roles[file] = "colour" if "colour" in (roles.get(file), role) else role
        material(doc, name, shader)
    write(doc, os.path.join(d, "models.mtlx"))
    with open(os.path.join(d, "models.json"), "w") as out:
        json.dump(roles, out, sort_keys=True)


if __name__ == "__main__":
    globals()[sys.argv[1]](sys.argv[2])
