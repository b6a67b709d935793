"""The USD half of specconv's asset reader (docs/assets.md). Pixar's usd-core composes the stage;
this module only reports what the stage says, and the library (crates/asset) decides.

    read(stage, extract_dir, replaceable)   the textures bound materials read; with a folder,
                                            textures inside a usdz package are copied there,
                                            replacing only the files `replaceable` names: those
                                            an asset run wrote
    layer(plan)                             the files of overrides, {"files": [{"path", "text"}]}:
                                            the layer (usda text) and the MaterialX documents'
                                            copies, which specconv writes

A MaterialX document (`.mtlx`), given or referenced where usd-core has no MaterialX file
format, is read by the MaterialX package (mtlx.py).
"""
import os

from .mtlx import (LOADED, MtlxError, document_text, load, materials_of, mtlx_textures,
                   read_document)
from .protocol import NO_MATERIALX, NO_USD, Failure, fail
from .shader_defs import DEFINITIONS, RAW_INPUTS, mtlx_module, typed

# A use is final at an input of a shading model (shader_defs.py) or of a node nothing reads
# on; a walk longer than this gives up.
MAX_DEPTH = 64


def shader_id(prim, UsdShade):
    shader = UsdShade.Shader(prim)
    if not shader:
        return None
    return str(shader.GetShaderId() or "") or None


def bound_materials(stage, Usd, UsdShade, want_targets):
    """The materials some prim is bound to, how many prims are bound, and (`want_targets`) the
    paths bindings name (a prim whose material is a MaterialX document this usd-core cannot
    open is no Material, but its path is bound)."""
    materials, bound, targets = {}, 0, set()
    predicate = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)
    for prim in stage.Traverse(predicate):
        if not prim.HasAPI(UsdShade.MaterialBindingAPI):
            continue
        api = UsdShade.MaterialBindingAPI(prim)
        named = set()
        for purpose in ("", "full", "preview") if want_targets else ():
            named.update(str(t) for t in api.GetDirectBindingRel(purpose).GetTargets())
        targets.update(named)
        material, _ = api.ComputeBoundMaterial()
        if material or named:
            bound += 1
        if material:
            materials.setdefault(str(material.GetPath()), material)
    return materials, bound, targets


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


def final_uses(edges, start, UsdShade):
    """The inputs that the output `start` feeds in the end, each with its type in the node's
    definition: followed through nodes that are no shading model (a normal-map node's `in`)
    to an input of a shading model or of a node nothing reads on."""
    uses, todo, seen = [], [(start, [])], set()
    while todo:
        port, through = todo.pop()
        if port in seen:
            continue
        if len(through) > MAX_DEPTH:
            # The walk gives up here: said as a use of its own, so nothing is decided.
            uses.append(dict(shader=port[0], shader_id=None, input="", through=through,
                             cut=True))
            continue
        seen.add(port)
        for consumer, name in edges.get(port, []):
            cpath = str(consumer.GetPath())
            sid = shader_id(consumer, UsdShade)
            definition = DEFINITIONS.of_id(sid)
            onward = [(cpath, o.GetBaseName()) for o in UsdShade.Shader(consumer).GetOutputs()]
            onward = [p for p in onward if p in edges]
            if not onward or (definition is not None and definition["model"]):
                uses.append(dict(shader=cpath, shader_id=sid, input=name, through=through,
                                 **typed(definition, name)))
            else:
                todo.extend((p, through + [cpath]) for p in onward)
    return uses


def mtlx_arcs(stage, Usd):
    """The references and payloads of the stage's prims that name a MaterialX document."""
    arcs, seen = [], set()
    for prim in stage.Traverse(Usd.TraverseInstanceProxies(Usd.PrimAllPrimsPredicate)):
        for spec in prim.GetPrimStack():
            for arc, proxy in (("references", spec.referenceList), ("payload", spec.payloadList)):
                items = list(proxy.explicitItems) + list(proxy.prependedItems) + \
                    list(proxy.appendedItems)
                for item in items:
                    if not item.assetPath.lower().endswith(".mtlx"):
                        continue
                    resolved = os.path.normpath(spec.layer.ComputeAbsolutePath(item.assetPath))
                    key = (str(prim.GetPath()), arc, resolved, str(item.primPath))
                    if key in seen:
                        continue
                    seen.add(key)
                    arcs.append(dict(prim=key[0], arc=arc, asset=item.assetPath,
                                     resolved=resolved, target=key[3],
                                     offset=item.layerOffset.offset,
                                     scale=item.layerOffset.scale))
    return arcs


def mtlx_materials(arc, targets):
    """The materials of a referenced document that bindings name (usdMtlx's paths: the
    document's material M is /MaterialX/Materials/M), as {name: bound path}."""
    root, target = arc["prim"], arc["target"] or "/MaterialX"
    names = {}
    for bound in sorted(targets):
        if bound != root and not bound.startswith(root + "/"):
            continue
        inside = (target.rstrip("/") + bound[len(root):]).split("/")
        if len(inside) == 4 and inside[1:3] == ["MaterialX", "Materials"]:
            names[inside[3]] = bound
    return names


def mtlx_referenced(stage, Usd, targets, errors):
    """The textures of the MaterialX documents the stage references, read by MaterialX, in
    the USD reader's form; the arcs; the composition errors left (a document's own failure to
    open is not one); the bound paths of the materials read."""
    arcs = mtlx_arcs(stage, Usd)
    if not arcs:
        return [], [], errors, []
    mx = mtlx_module()
    if mx is None:
        fail("no-materialx", arcs[0]["resolved"], status=NO_MATERIALX)
    handled = ["@%s@" % a["resolved"] for a in arcs]
    errors = [e for e in errors if not any(h in e for h in handled)]
    textures, used, paths, wanted = [], [], [], {}
    for arc in arcs:
        names = mtlx_materials(arc, targets)
        if not names:
            continue
        inside = packaged(arc["resolved"])
        if inside is not None:
            # MaterialX reads files, and usd-core's resolver alone opens a package's members.
            fail("package", "%s references the MaterialX document '%s' inside the usdz %s: "
                 "specconv asset does not read a .mtlx inside a usdz; unpack the package "
                 "(unzip it) and run on its stage" % (arc["prim"], inside[1], inside[0]))
        try:
            doc = load(mx, arc["resolved"])
        except MtlxError as e:
            fail(e.args[0], "%s (referenced by %s)" % (e.args[1], arc["prim"]))
        found = materials_of(mx, doc)
        chosen = {n: (found[n][0], bound) for n, bound in names.items() if n in found}
        # A prim may reference several documents: a material is missing only if none has it.
        for n, bound in names.items():
            wanted.setdefault(bound, []).append(n in found)
        paths += [bound for _, bound in chosen.values()]
        textures += mtlx_textures(mx, doc, os.path.dirname(arc["resolved"]), chosen,
                                  MAX_DEPTH, arc["resolved"])
        used.append(arc)
    for bound, has in sorted(wanted.items()):
        if not any(has):
            errors.append("%s is bound, and no MaterialX document its prim references has the "
                          "material" % bound)
    return textures, used, errors, paths


def file_of(prim, name, UsdShade, Sdf):
    """The texture's file input `name`: as authored, resolved, and where it came from."""
    inp = UsdShade.Shader(prim).GetInput(name)
    if not inp:
        return None
    attr = inp.GetAttr()
    value = attr.Get()
    if value is None:
        return dict(authored=None, resolved=None, colorspace=None, layer=None, file_input=name)
    spec = next(iter(attr.GetPropertyStack()), None)
    layer = spec.layer if spec is not None else None
    if not isinstance(value, (str, Sdf.AssetPath)):
        fail("file", "%s.inputs:%s is typed %s, not a path: author the file as an asset path "
             "(asset inputs:%s = @./tex/name.png@)"
             % (prim.GetPath(), name, attr.GetTypeName(), name))
    if isinstance(value, str):
        # A file input typed string (as Arnold's and RenderMan's definitions type them): a
        # path all the same, anchored to the layer that wrote it, as an asset path is.
        authored = value
        anchored = layer.ComputeAbsolutePath(value) if layer is not None and value else value
        resolved = anchored if value and os.path.exists(anchored) else None
    else:
        authored = value.path
        resolved = value.resolvedPath or None
    if resolved is None and "<UDIM>" in authored.upper() and layer is not None:
        # A UDIM pattern names no one file: anchored to its layer as the tiles are.
        anchored = layer.ComputeAbsolutePath(authored)
        resolved = anchored if os.path.isabs(anchored) else None
    looked_for = layer.ComputeAbsolutePath(authored) if layer is not None and authored \
        else None
    return dict(authored=authored, resolved=resolved,
                colorspace=attr.GetColorSpace() or None, file_input=name,
                layer=layer.realPath if layer is not None else None, looked_for=looked_for)


def declared_space(prim, sid, f):
    """The colour space a texture node declares for its file, in the library's two words:
    `source_color_space` (UsdUVTexture's `sourceColorSpace`; PxrTexture's `linearize` 1, the
    reverse sRGB transform, is `sRGB`) and `colorspace` (the file input's `colorSpace`;
    Arnold's image `color_space` other than `auto`)."""
    def value(name):
        attr = prim.GetAttribute("inputs:" + name)
        return attr.Get() if attr and attr.HasAuthoredValue() else None

    scs, cs = value("sourceColorSpace"), f.pop("colorspace")
    if sid in ("PxrTexture", "PxrMultiTexture") and value("linearize") == 1:
        scs = "sRGB"
    if sid == "arnold:image":
        named = value("color_space")
        cs = named if named and named.lower() != "auto" else cs
    return dict(source_color_space=scs or None, colorspace=cs or None)


def packaged(resolved):
    """(package, member) of a path inside a usdz package (`a.usdz[tex/b.png]`), else None."""
    if resolved and resolved.endswith("]") and "[" in resolved:
        package, member = resolved[:-1].split("[", 1)
        return package, member
    return None


def member_path(member):
    """The folders and name a usdz member is copied out to, one member one path (issue 57,
    item 4): a `%` is written `%25` and a backslash `%5C`, and a part that is no name (empty,
    `.`, `..`) is `%`, `%2E`, `%2E%2E`, so nothing leaves the folder, and `../a.png` is not
    `a.png`. A plain name (`tex/a.png`) is kept as it is."""
    parts = member.replace("%", "%25").replace("\\", "%5C").split("/")
    return [{"": "%", ".": "%2E", "..": "%2E%2E"}.get(p, p) for p in parts]


def extract(resolved, member, into, Ar, replaceable):
    """Copies a packaged texture out of its usdz into `into` (specconv's output directory).
    A file already there is replaced only when an asset run wrote it (`replaceable`, from the
    record the library keeps); one with the member's bytes is kept as it is."""
    target = os.path.join(into, *member_path(member))
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
    if os.path.lexists(target) and os.path.abspath(target) not in replaceable:
        fail("not-ours", os.path.abspath(target))
    tmp = target + ".specconv-tmp-%d" % os.getpid()
    with open(tmp, "wb") as out:
        out.write(data)
    os.replace(tmp, target)
    return target


def read(stage_path, extract_dir, replaceable=()):
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
    # usd-core without its MaterialX file format fails to open every .mtlx it is referred to,
    # so only then are the documents looked for (a walk over every prim's specs).
    mtlx = Sdf.FileFormat.FindByExtension("mtlx") is None \
        and any(".mtlx" in e.lower() for e in errors)
    materials, bound, targets = bound_materials(stage, Usd, UsdShade, mtlx)
    textures, references, materials_read, unknown = [], [], 0, []
    if mtlx:
        # usd-core without its MaterialX file format: the documents are read by MaterialX.
        textures, references, errors, read_paths = mtlx_referenced(stage, Usd, targets, errors)
        materials_read = len(set(read_paths) - set(materials))
    for mpath, material in sorted(materials.items()):
        edges, shaders = network(material, UsdShade)
        for path in sorted(shaders):
            prim = stage.GetPrimAtPath(path)
            sid = shader_id(prim, UsdShade)
            definition = DEFINITIONS.of_id(sid)
            if definition is None or not definition["files"]:
                unknown += unknown_reads(prim, sid, mpath, UsdShade, Sdf)
                continue
            files = [f for f in (file_of(prim, n, UsdShade, Sdf) for n in definition["files"])
                     if f]
            if len(definition["files"]) > 1:  # PxrMultiTexture: the files it is given
                files = [f for f in files if f["authored"]]
            if not files:
                continue
            # A node inside its material gets a copy in the spectral network, where a data use
            # can keep reading the original node; one outside gets a direct override.
            inseparable = None if path.startswith(mpath + "/") else \
                "the texture node %s is outside its material %s" % (path, mpath)
            uses = []
            for output in UsdShade.Shader(prim).GetOutputs():
                for use in final_uses(edges, (path, output.GetBaseName()), UsdShade):
                    uses.append(dict(use, material=mpath, output=output.GetBaseName(),
                                     inseparable=inseparable))
            for f in files:
                entry = dict(node=path, node_id=sid, package=None, uses=uses,
                             raw_input=RAW_INPUTS.get(sid), **declared_space(prim, sid, f),
                             **f)
                pkg = packaged(f["resolved"])
                if pkg is not None:
                    entry["package"] = dict(file=pkg[0], member=pkg[1])
                    if extract_dir is not None:
                        entry["resolved"] = extract(f["resolved"], pkg[1], extract_dir, Ar,
                                                    replaceable)
                textures.append(entry)
    # Every layer composed (a usdz member as its package) and MaterialX file loaded: what the
    # library never lets an output be.
    layers = [l.realPath.split("[", 1)[0] for l in stage.GetUsedLayers() if l.realPath]
    read_files = sorted(set(os.path.abspath(p) for p in layers + LOADED))
    return dict(stage=os.path.abspath(stage_path), materials=len(materials) + materials_read,
                bound_prims=bound, composition_errors=errors, textures=textures,
                references=references, read_files=read_files, unknown=unknown)


def unknown_reads(prim, sid, material, UsdShade, Sdf):
    """The files a shader that is no known texture node reads (an `asset` input with a path:
    Arnold's `image`, RenderMan's `PxrTexture`, …): reported, never converted or ignored in
    silence (issue 56, item 2)."""
    found = []
    for inp in UsdShade.Shader(prim).GetInputs():
        value = inp.Get()
        if isinstance(value, Sdf.AssetPath) and value.path:
            found.append(dict(node=str(prim.GetPath()), node_id=sid or prim.GetTypeName() or None,
                              input=inp.GetBaseName(), file=value.path,
                              resolved=value.resolvedPath or None, material=material))
    return found


def usd_layer(plan):
    """The layer over the stage as usda text: the spectral files behind UsdShade's render
    context `spectral` (docs/assets.md, "The switch")."""
    from pxr import Sdf, Tf, Usd, UsdShade
    try:
        out = Sdf.Layer.CreateAnonymous(".usda")
        out.subLayerPaths.append(plan["sublayer"])
        context = plan["render_context"]
        out.customLayerData = {"specconv": {"stage": plan["sublayer"],
                                            "renderContext": context}}
        # The stage's defaultPrim, so that the layer is referenced as the stage is, without a
        # prim path.
        root = Sdf.Layer.FindOrOpen(plan["stage"])
        if root is not None and root.defaultPrim:
            out.defaultPrim = root.defaultPrim
        if plan["overrides"]:
            stage = Usd.Stage.Open(plan["stage"], Usd.Stage.LoadAll)
            spectral_networks(out, stage, plan["overrides"], context, Sdf, Usd, UsdShade)
        for r in plan.get("references", []):
            retarget(out, r, plan["variant_set"], context, Sdf)
        return out.ExportToString()
    except Tf.ErrorException as e:
        fail("layer", str(e).strip())


def set_spectral_file(prim, o, Sdf):
    """A texture node's copy reads the spectral file `o` names, as written (raw)."""
    name = "inputs:" + o["file_input"]
    if name in prim.attributes and prim.attributes[name].typeName != Sdf.ValueTypeNames.Asset:
        # A file input typed string or token (RenderMan's, Arnold's) keeps its type.
        attr = prim.attributes[name]
        attr.default = o["file"]
    else:
        attr = prim.attributes[name] if name in prim.attributes else \
            Sdf.AttributeSpec(prim, name, Sdf.ValueTypeNames.Asset)
        attr.default = Sdf.AssetPath(o["file"])
    # Read back as customData key paths `specconv:original`, `specconv:originalResolved`.
    attr.customData = {"specconv": {k: v for k, v in (
        ("original", o["original"]), ("originalResolved", o["original_resolved"]),
        ("originalColorSpace", o.get("original_colorspace"))) if v is not None}}
    if o.get("original_colorspace") is not None:
        # MaterialX's colorspace would convert the spectra from that space: read them as
        # written instead, as sourceColorSpace raw does for a UsdUVTexture.
        attr.SetInfo("colorSpace", "raw")
    if o.get("raw_input"):
        # The spectral file holds linear reflectance: nothing may decode it (shader_defs.py).
        raw, type_name, value = o["raw_input"]
        name = "inputs:" + raw
        if name in prim.attributes:
            prim.attributes[name].default = value
        else:
            Sdf.AttributeSpec(prim, name, Sdf.ValueTypeNames.Find(type_name)).default = value


def spectral_networks(out, stage, overrides, context, Sdf, Usd, UsdShade):
    """For each material whose network reads a converted colour texture, a copy of the part of
    that network the spectral files change (every child of the material from which a
    connection leads to such a texture node: shaders, node graphs whole), beside the original
    as `NAME_spectral`, its texture nodes reading the spectral files, and the material's
    terminals for the render context `spectral` (`outputs:spectral:surface` …) connected to the
    copies. The original network, which every RGB renderer reads, is not touched. A texture
    node outside any material keeps the direct override (no render context can reach it)."""
    groups = {}
    for o in overrides:
        node = o["node"]
        prim = stage.GetPrimAtPath(node)
        m = prim.GetParent() if prim else None
        while m and not m.IsPseudoRoot() and not m.IsA(UsdShade.Material):
            m = m.GetParent()
        if not m or m.IsPseudoRoot():
            spec = Sdf.CreatePrimInLayer(out, Sdf.Path(node))
            spec.specifier = Sdf.SpecifierOver
            attr = prim.GetAttribute("inputs:" + o["file_input"]) if prim else None
            if attr:  # the override keeps the file input's type
                Sdf.AttributeSpec(spec, attr.GetName(), attr.GetTypeName())
            set_spectral_file(spec, o, Sdf)
            continue
        groups.setdefault(m.GetPath(), []).append(o)
    for mpath, group in sorted(groups.items()):
        copy_network(out, stage.GetPrimAtPath(mpath), group, context, Sdf, Usd, UsdShade)


def copy_network(out, material, overrides, render_context, Sdf, Usd, UsdShade):
    mpath = material.GetPath()
    depth = mpath.pathElementCount + 1

    def unit(path):
        """The material's child on `path` (None outside the material)."""
        if not path.HasPrefix(mpath) or path.pathElementCount < depth:
            return None
        while path.pathElementCount > depth:
            path = path.GetParentPath()
        return path

    # Which children lead, by connections, to a converted texture node.
    edges = set()
    for prim in Usd.PrimRange(material):
        for attr in prim.GetAttributes():
            for target in attr.GetConnections():
                a, b = unit(prim.GetPath()), unit(target.GetPrimPath())
                if a is not None and b is not None and a != b:
                    edges.add((a, b))
    tainted = {unit(Sdf.Path(o["node"])) for o in overrides}
    grew = True
    while grew:
        grew = False
        for a, b in edges:
            if b in tainted and a not in tainted:
                tainted.add(a)
                grew = True
    names = {c.GetName() for c in material.GetChildren()}
    renamed = {}
    for u in sorted(tainted):
        name = u.name + "_spectral"
        while name in names:
            name += "_"
        names.add(name)
        renamed[u] = mpath.AppendChild(name)

    def mapped(path):
        """A path into a copied child, in its copy; any other path as it is."""
        u = unit(path.GetPrimPath())
        return path.ReplacePrefix(u, renamed[u]) if u in renamed else path

    # A data use of a converted texture keeps its input connected to the original network,
    # which reads the original file.
    kept = {(k["shader"], "inputs:" + k["input"]) for o in overrides for k in o["keep"]}
    for u in sorted(tainted):
        for prim in Usd.PrimRange(material.GetStage().GetPrimAtPath(u)):
            copy_prim(out, prim, mapped, Sdf, kept)
    for o in overrides:
        spec = out.GetPrimAtPath(mapped(Sdf.Path(o["node"])))
        set_spectral_file(spec, o, Sdf)
    # The material's terminals for the spectral render context, where the copy feeds them:
    # from the universal terminal (`outputs:surface`), else from a render context's
    # (`outputs:mtlx:surface` first: a MaterialX-in-USD material may have no other).
    terminals = {}
    for output in UsdShade.Material(material).GetOutputs():
        context, _, terminal = output.GetBaseName().rpartition(":")
        sources = list(output.GetAttr().GetConnections())
        copies = [mapped(t) for t in sources]
        if context == render_context or copies == sources:  # ours, or not reached by the copy
            continue
        rank = {"": 0, "mtlx": 1}.get(context, 2)
        if terminal not in terminals or rank < terminals[terminal][0]:
            terminals[terminal] = (rank, output.GetAttr().GetTypeName(), copies)
    if terminals:
        over = Sdf.CreatePrimInLayer(out, mpath)
        over.specifier = Sdf.SpecifierOver
    for terminal, (_, type_name, copies) in sorted(terminals.items()):
        attr = Sdf.AttributeSpec(over, "outputs:%s:%s" % (render_context, terminal), type_name)
        attr.connectionPathList.explicitItems = copies


def copy_prim(out, prim, mapped, Sdf, kept):
    """The composed prim `prim` as a new prim at its mapped path: its type, applied schemas,
    and every authored attribute's value and connections (mapped, but those of the inputs
    `kept` names, which stay on the original network), a record of what it copies."""
    spec = Sdf.CreatePrimInLayer(out, mapped(prim.GetPath()))
    spec.specifier = Sdf.SpecifierDef
    spec.typeName = prim.GetTypeName()
    schemas = prim.GetAppliedSchemas()
    if schemas:
        spec.SetInfo("apiSchemas", Sdf.TokenListOp.CreateExplicit(list(schemas)))
    spec.customData = {"specconv": {"copyOf": str(prim.GetPath())}}
    for attr in prim.GetAttributes():
        connections = attr.GetConnections()
        if not attr.IsAuthored():  # a schema's fallback: the copy has it too
            continue
        a = Sdf.AttributeSpec(spec, attr.GetName(), attr.GetTypeName(), attr.GetVariability())
        if attr.HasAuthoredValue():
            a.default = attr.Get()
        if attr.HasColorSpace():
            a.SetInfo("colorSpace", attr.GetColorSpace())
        if connections:
            keep = (str(prim.GetPath()), attr.GetName()) in kept
            a.connectionPathList.explicitItems = [t if keep else mapped(t) for t in connections]


def retarget(out, r, variant_set, choice, Sdf):
    """A reference (or payload) to a MaterialX document, switched: the variant set
    `variant_set` (spectralTextures) on its prim, `rgb` selected (nothing added: every renderer
    reads the document as the stage does), and `choice` (the render context's name, spectral),
    which adds one to the document's copy. The copy's opinions, under a variant of the prim,
    are stronger than the original reference's (USD's LIVRPS), so with that choice every prim
    of the document is the copy's. A document's material has no network of its own to copy
    for a render context."""
    prim = out.GetPrimAtPath(r["prim"])
    if prim is None:
        prim = Sdf.CreatePrimInLayer(out, Sdf.Path(r["prim"]))
        prim.specifier = Sdf.SpecifierOver
    if variant_set not in prim.variantSets:
        vset = Sdf.VariantSetSpec(prim, variant_set)
        for name in ("rgb", choice):
            Sdf.VariantSpec(vset, name)
        prim.variantSetNameList.Prepend(variant_set)
        prim.variantSelections[variant_set] = "rgb"
    spectral = prim.variantSets[variant_set].variants[choice].primSpec
    target = Sdf.Path(r["target"]) if r["target"] else Sdf.Path()
    offset = Sdf.LayerOffset(r["offset"], r["scale"])
    if r["arc"] == "payload":
        spectral.payloadList.Append(Sdf.Payload(r["file"], target, offset))
    else:
        spectral.referenceList.Append(Sdf.Reference(r["file"], target, offset))
    from pxr import Vt
    originals = dict(prim.customData.get("specconv", {}))
    originals["originalReferences"] = Vt.StringArray(
        list(originals.get("originalReferences", [])) + [r["asset"]])
    prim.customData = {"specconv": originals}


def read_any(stage_path, extract_dir, replaceable):
    """`read` of a stage, or of a MaterialX document given alone."""
    if stage_path.lower().endswith(".mtlx"):
        need_materialx(stage_path)
        try:
            return read_document(stage_path, MAX_DEPTH)
        except MtlxError as e:
            fail(*e.args)
    need_usd()
    return read(stage_path, extract_dir, set(replaceable))


def layer(plan):
    """The files of overrides of `plan`, {"files": [{path, text}]}: the MaterialX override
    documents, then the USD layer (none for a document given alone); specconv writes them."""
    files = []
    for d in plan.get("documents", []):
        need_materialx(d["source"])
        try:
            files.append(dict(path=d["layer"], text=document_text(d["source"], d["overrides"])))
        except MtlxError as e:
            fail(*e.args)
    if not plan["stage"].lower().endswith(".mtlx"):
        need_usd()
        files.append(dict(path=plan["layer"], text=usd_layer(plan)))
    return dict(files=files)


def need_usd():
    try:
        import pxr  # noqa: F401
        from pxr import Usd  # noqa: F401
    except ImportError as e:
        raise Failure(NO_USD, dict(error="no-pxr", detail=str(e)))


def need_materialx(document):
    if mtlx_module() is None:
        fail("no-materialx", document, status=NO_MATERIALX)
