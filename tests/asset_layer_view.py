"""What usd-core makes of the layer `specconv asset` wrote (issue 56, item 1), two ways:

    asset_layer_view.py LAYER

- with no choice made (what every RGB renderer reads): every file input of every prim of the
  stage alone (`inputs:file`, `inputs:filename`, `inputs:filename0`…) has the same value in
  the layer composed over it, and every material the
  same surface source; the mismatches are listed under "rgb_changed" (none expected);
- with the spectral choice (UsdShade's render context `spectral`): each texture node's
  file inputs as the network of that context reads them, the node's copy where the layer made
  one (customData `specconv:copyOf`), else the node itself; under "files", keyed by the
  original node's path, with the attribute's customData and colour space.

Prints JSON: {"files": …, "rgb_changed": […], "sublayers": […], "contexts": {material: path}}.
"""
import json
import re
import sys

from pxr import Sdf, Usd, UsdShade


def file_inputs(prim):
    """A prim's file inputs with a value, {name: path}: `inputs:file`, Arnold's and RenderMan's
    `inputs:filename`, PxrMultiTexture's `inputs:filename0`…, typed asset, string or token."""
    found = {}
    for a in prim.GetAttributes():
        name = a.GetName()
        if name == "inputs:file" or re.fullmatch(r"inputs:filename\d?", name):
            v = a.Get()
            if v is not None:
                found[name] = v.path if isinstance(v, Sdf.AssetPath) else str(v)
    return found


def key(prim, name):
    """A file input's key in "files": the node's path, `PATH.inputs:filenameN` for all but a
    node's only file input."""
    return str(prim.GetPath()) if name in ("inputs:file", "inputs:filename") \
        else "%s.%s" % (prim.GetPath(), name)


def main(path):
    layer = Sdf.Layer.FindOrOpen(path)
    stage = Usd.Stage.Open(path)
    alone = Usd.Stage.Open(layer.ComputeAbsolutePath(layer.subLayerPaths[0]))
    changed = []
    for p in alone.Traverse():
        mine = file_inputs(stage.GetPrimAtPath(p.GetPath()))
        for name, value in file_inputs(p).items():
            if mine.get(name) != value:
                changed.append(key(p, name))
        if p.IsA(UsdShade.Material):
            before = UsdShade.Material(p).ComputeSurfaceSource("")[0]
            after = UsdShade.Material(stage.GetPrimAtPath(p.GetPath())).ComputeSurfaceSource("")[0]
            if (before.GetPath() if before else None) != (after.GetPath() if after else None):
                changed.append(str(p.GetPath()) + " (surface)")
    copies, contexts = {}, {}
    for p in stage.Traverse():
        of = p.GetCustomDataByKey("specconv:copyOf")
        if of:
            copies[of] = p
        if p.IsA(UsdShade.Material):
            src = UsdShade.Material(p).ComputeSurfaceSource("spectral")[0]
            contexts[str(p.GetPath())] = str(src.GetPath()) if src else None
    files = {}
    for p in stage.Traverse():
        if p.GetCustomDataByKey("specconv:copyOf"):
            continue
        node = copies.get(str(p.GetPath()), p)
        for name, value in file_inputs(node).items():
            a = node.GetAttribute(name)
            scs = node.GetAttribute("inputs:sourceColorSpace")
            resolved = a.Get().resolvedPath if isinstance(a.Get(), Sdf.AssetPath) else None
            raw = {n: node.GetAttribute("inputs:" + n).Get() for n in
                   ("sourceColorSpace", "linearize", "color_space")
                   if node.GetAttribute("inputs:" + n).HasAuthoredValue()}
            files[key(p, name)] = dict(
                file=value, resolved=resolved, copy=str(node.GetPath()) if node != p else None,
                original=a.GetCustomDataByKey("specconv:original"),
                cs=a.GetColorSpace() or None,
                original_cs=a.GetCustomDataByKey("specconv:originalColorSpace"),
                scs=scs.Get() if scs else None, raw=raw, type=str(a.GetTypeName()))
    print(json.dumps(dict(files=files, rgb_changed=changed, contexts=contexts,
                          sublayers=list(layer.subLayerPaths))))


if __name__ == "__main__":
    main(sys.argv[1])
