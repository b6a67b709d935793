"""specconv's USD reader (docs/assets.md), run by `specconv asset` with the interpreter that
$SPECCONV_USD_PYTHON names (else python3). Pixar's usd-core composes the stage; this script
only reports what the stage says, and the library (crates/asset) decides.

    read STAGE INPUTS [DIR]    prints the textures bound materials read, as one JSON object;
                               INPUTS (a JSON list) are the material inputs a use ends at; with
                               DIR, textures inside a usdz package are copied there
    layer                      reads a plan (JSON) on stdin and prints the layer of overrides
                               (usda text), which specconv writes

Exit status 3: usd-core (the pxr module) is missing. Any other failure is a JSON object with
"error" on stdout, exit status 2.
"""
import json
import os
import sys

TEXTURE_IDS = ("UsdUVTexture",)
TEXTURE_PREFIXES = ("ND_image_", "ND_tiledimage_", "ND_hextiledimage_", "ND_gltf_image_",
                    "ND_gltf_colorimage")
# A use is final at an input of these names (the decision's lists) or at a node nothing reads.
MAX_DEPTH = 64


def fail(kind, detail, **more):
    print(json.dumps(dict(error=kind, detail=detail, **more)))
    sys.exit(2)


def shader_id(prim, UsdShade):
    shader = UsdShade.Shader(prim)
    if not shader:
        return None
    return str(shader.GetShaderId() or "") or None


def is_texture(sid):
    return sid is not None and (sid in TEXTURE_IDS or sid.startswith(TEXTURE_PREFIXES))


def bound_materials(stage, Usd, UsdShade):
    """The materials some prim is bound to, and how many prims are bound."""
    materials, bound = {}, 0
    predicate = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)
    for prim in stage.Traverse(predicate):
        if not prim.HasAPI(UsdShade.MaterialBindingAPI):
            continue
        material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
        if material:
            bound += 1
            materials.setdefault(str(material.GetPath()), material)
    return materials, bound


def network(material, UsdShade):
    """Edges (producer prim, output) -> [(consumer prim, input)] of the shaders the material's
    outputs read, through node graphs (GetValueProducingAttributes)."""
    edges, seen, todo = {}, set(), []

    def producers(port):
        return UsdShade.Utils.GetValueProducingAttributes(port, shaderOutputsOnly=True)

    for output in material.GetOutputs():
        for attr in producers(output):
            todo.append(attr.GetPrim())
    while todo:
        prim = todo.pop()
        path = str(prim.GetPath())
        if path in seen:
            continue
        seen.add(path)
        for inp in UsdShade.Shader(prim).GetInputs():
            for attr in producers(inp):
                name = UsdShade.Utils.GetBaseNameAndType(attr.GetName())[0]
                source = attr.GetPrim()
                edges.setdefault((str(source.GetPath()), name), []).append(
                    (prim, inp.GetBaseName()))
                todo.append(source)
    return edges, seen


def final_uses(edges, start, final_inputs, UsdShade):
    """The inputs that the output `start` feeds in the end: followed through nodes whose input
    is not a known one (a normal-map node's `in`), to the input of a node nothing reads on."""
    uses, todo, seen = [], [(start, [])], set()
    while todo:
        port, through = todo.pop()
        if port in seen or len(through) > MAX_DEPTH:
            continue
        seen.add(port)
        for consumer, name in edges.get(port, []):
            cpath = str(consumer.GetPath())
            onward = [(cpath, o.GetBaseName()) for o in UsdShade.Shader(consumer).GetOutputs()]
            onward = [p for p in onward if p in edges]
            if name in final_inputs or not onward:
                uses.append(dict(shader=cpath, shader_id=shader_id(consumer, UsdShade),
                                 input=name, through=through))
            else:
                todo.extend((p, through + [cpath]) for p in onward)
    return uses


def file_of(prim, UsdShade, Sdf):
    """The texture's file: as authored, resolved, and where it came from."""
    inp = UsdShade.Shader(prim).GetInput("file")
    if not inp:
        return None
    attr = inp.GetAttr()
    value = attr.Get()
    if value is None:
        return dict(authored=None, resolved=None, colorspace=None, layer=None)
    authored = value.path
    resolved = value.resolvedPath or None
    spec = next(iter(attr.GetPropertyStack()), None)
    layer = spec.layer if spec is not None else None
    if resolved is None and "<UDIM>" in authored.upper() and layer is not None:
        # A UDIM pattern names no one file: anchored to its layer as the tiles are.
        anchored = layer.ComputeAbsolutePath(authored)
        resolved = anchored if os.path.isabs(anchored) else None
    return dict(authored=authored, resolved=resolved,
                colorspace=attr.GetColorSpace() or None,
                layer=layer.realPath if layer is not None else None)


def packaged(resolved):
    """(package, member) of a path inside a usdz package (`a.usdz[tex/b.png]`), else None."""
    if resolved and resolved.endswith("]") and "[" in resolved:
        package, member = resolved[:-1].split("[", 1)
        return package, member
    return None


def extract(resolved, member, into, Ar):
    """Copies a packaged texture out of its usdz into `into` (specconv's output directory)."""
    safe = [p for p in member.replace("\\", "/").split("/") if p not in ("", ".", "..")]
    target = os.path.join(into, *safe) if safe else None
    if target is None:
        fail("package", "a usdz member with no usable name: " + member)
    asset = Ar.GetResolver().OpenAsset(Ar.ResolvedPath(resolved))
    if asset is None:
        fail("package", "cannot read " + resolved + " from its usdz package")
    os.makedirs(os.path.dirname(target), exist_ok=True)
    data = bytes(asset.GetBuffer())
    # A copy already there with these bytes is kept: rewriting it would make every output
    # converted from it look out of date to -u (and to a farm job's collect).
    if os.path.isfile(target) and not os.path.islink(target) \
            and os.path.getsize(target) == len(data):
        with open(target, "rb") as have:
            if have.read() == data:
                return target
    tmp = target + ".specconv-tmp-%d" % os.getpid()
    with open(tmp, "wb") as out:
        out.write(data)
    os.replace(tmp, target)
    return target


def read(stage_path, extract_dir, final_inputs):
    from pxr import Usd, UsdShade, Sdf, Ar, Tf
    try:
        stage = Usd.Stage.Open(stage_path, Usd.Stage.LoadAll)
    except Tf.ErrorException as e:
        fail("open", str(e).strip())
    if stage is None:
        fail("open", "usd-core could not open the stage")
    # A reference cycle, a layer that cannot be read: composition went on without it, so a
    # texture may be missing from the list; the library refuses the stage.
    errors = [" ".join(str(e).split()) for e in stage.GetCompositionErrors()]
    materials, bound = bound_materials(stage, Usd, UsdShade)
    textures = []
    for mpath, material in sorted(materials.items()):
        edges, shaders = network(material, UsdShade)
        for path in sorted(shaders):
            prim = stage.GetPrimAtPath(path)
            sid = shader_id(prim, UsdShade)
            if not is_texture(sid):
                continue
            f = file_of(prim, UsdShade, Sdf)
            if f is None:
                continue
            uses = []
            for output in UsdShade.Shader(prim).GetOutputs():
                for use in final_uses(edges, (path, output.GetBaseName()), final_inputs,
                                      UsdShade):
                    uses.append(dict(use, material=mpath, output=output.GetBaseName()))
            scs = UsdShade.Shader(prim).GetInput("sourceColorSpace")
            scs = scs.Get() if scs else None
            pkg = packaged(f["resolved"])
            entry = dict(node=path, node_id=sid, source_color_space=scs or None,
                         package=None, uses=uses, **f)
            if pkg is not None:
                entry["package"] = dict(file=pkg[0], member=pkg[1])
                if extract_dir is not None:
                    entry["resolved"] = extract(f["resolved"], pkg[1], extract_dir, Ar)
            textures.append(entry)
    print(json.dumps(dict(stage=os.path.abspath(stage_path), materials=len(materials),
                          bound_prims=bound, composition_errors=errors, textures=textures)))


def layer():
    """Prints the layer of overrides as usda text; specconv writes it (atomically, beside it)."""
    from pxr import Sdf, Tf
    plan = json.load(sys.stdin)
    try:
        out = Sdf.Layer.CreateAnonymous(".usda")
        out.subLayerPaths.append(plan["sublayer"])
        out.customLayerData = {"specconv": {"stage": plan["stage"]}}
        for o in plan["overrides"]:
            prim = Sdf.CreatePrimInLayer(out, Sdf.Path(o["node"]))
            prim.specifier = Sdf.SpecifierOver
            attr = Sdf.AttributeSpec(prim, "inputs:file", Sdf.ValueTypeNames.Asset)
            attr.default = Sdf.AssetPath(o["file"])
            # Read back as customData key paths `specconv:original`, `specconv:originalResolved`.
            attr.customData = {"specconv": {k: v for k, v in (
                ("original", o["original"]), ("originalResolved", o["original_resolved"]),
                ("originalColorSpace", o.get("original_colorspace"))) if v is not None}}
            if o.get("original_colorspace") is not None:
                # MaterialX's colorspace would convert the spectra from that space: read them
                # as written instead, as sourceColorSpace raw does for a UsdUVTexture.
                attr.SetInfo("colorSpace", "raw")
            if o.get("raw"):
                # The spectral file holds linear reflectance: nothing may sRGB-decode it.
                scs = Sdf.AttributeSpec(prim, "inputs:sourceColorSpace",
                                        Sdf.ValueTypeNames.Token)
                scs.default = "raw"
        sys.stdout.write(out.ExportToString())
    except Tf.ErrorException as e:
        fail("layer", str(e).strip())


def main():
    try:
        import pxr  # noqa: F401
        from pxr import Usd  # noqa: F401
    except ImportError as e:
        print(json.dumps(dict(error="no-pxr", detail=str(e))))
        return 3
    if len(sys.argv) in (4, 5) and sys.argv[1] == "read":
        final_inputs = set(json.loads(sys.argv[3]))
        read(sys.argv[2], sys.argv[4] if len(sys.argv) == 5 else None, final_inputs)
    elif len(sys.argv) == 2 and sys.argv[1] == "layer":
        layer()
    else:
        fail("usage", "read STAGE INPUTS [DIR] | layer")
    return 0


if __name__ == "__main__":
    sys.exit(main())
