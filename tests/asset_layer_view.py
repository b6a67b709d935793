"""What usd-core makes of the layer `specconv asset` wrote (issue 56, item 1), two ways:

    asset_layer_view.py LAYER

- with no choice made (what every RGB renderer reads): every prim of the stage alone that has
  an `inputs:file` has the same value in the layer composed over it, and every material the
  same surface source; the mismatches are listed under "rgb_changed" (none expected);
- with the spectral choice (UsdShade's render context `spectral`): each texture node's
  `inputs:file` as the network of that context reads it, the node's copy where the layer made
  one (customData `specconv:copyOf`), else the node itself; under "files", keyed by the
  original node's path, with the attribute's customData and colour space.

Prints JSON: {"files": …, "rgb_changed": […], "sublayers": […], "contexts": {material: path}}.
"""
import json
import sys

from pxr import Sdf, Usd, UsdShade


def main(path):
    layer = Sdf.Layer.FindOrOpen(path)
    stage = Usd.Stage.Open(path)
    alone = Usd.Stage.Open(layer.ComputeAbsolutePath(layer.subLayerPaths[0]))
    changed = []
    for p in alone.Traverse():
        a = p.GetAttribute("inputs:file")
        if a and a.Get() is not None:
            mine = stage.GetPrimAtPath(p.GetPath()).GetAttribute("inputs:file").Get()
            if mine is None or mine.path != a.Get().path:
                changed.append(str(p.GetPath()))
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
        a = node.GetAttribute("inputs:file")
        if not a or a.Get() is None:
            continue
        v = a.Get()
        scs = node.GetAttribute("inputs:sourceColorSpace")
        files[str(p.GetPath())] = dict(
            file=v.path, resolved=v.resolvedPath, copy=str(node.GetPath()) if node != p else None,
            original=a.GetCustomDataByKey("specconv:original"),
            cs=a.GetColorSpace() or None,
            original_cs=a.GetCustomDataByKey("specconv:originalColorSpace"),
            scs=scs.Get() if scs else None)
    print(json.dumps(dict(files=files, rgb_changed=changed, contexts=contexts,
                          sublayers=list(layer.subLayerPaths))))


if __name__ == "__main__":
    main(sys.argv[1])
