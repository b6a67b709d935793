"""Shader definitions (docs/assets.md, "Roles from shader definitions"), for the asset reader's
two halves (mtlx.py, stage.py). A texture's role is decided by the library from the TYPE that
the definition of the shader it reaches gives the input (`color3` is colour, `float` data),
never from the input's name. Definitions come from where each renderer publishes them:

- USD's own shaders (UsdPreviewSurface, UsdUVTexture): usd-core's shader registry (Sdr), from
  the shaderDefs.usda usd-core ships.
- MaterialX nodes (`ND_*` ids in USD, nodes of a `.mtlx` document): the document's own
  nodedefs, else the standard library the MaterialX package ships (standard_surface,
  open_pbr_surface, gltf_pbr, the BSDFs, image nodes).
- Arnold and RenderMan, whose definitions ship only with the renderers: the tables below,
  each with its source.

A definition says whether the node is a shading model (where the walk from a texture stops),
each input's type in the renderer's own words, and which inputs name files (a node with one
is a texture node).
"""


def mtlx_module():
    """The MaterialX package, else None (the reader says so only where a document is read)."""
    try:
        import MaterialX as mx
    except ImportError:
        return None
    return mx


# MaterialX types of a shading model's output (MaterialX specification, "Shader Nodes").
MX_MODEL_TYPES = ("surfaceshader", "displacementshader", "volumeshader", "lightshader",
                  "material", "BSDF", "EDF", "VDF")

# Arnold's standard_surface, its parameters' Arnold types. Sources: the parameter types
# arnold-usd (Autodesk/arnold-usd) writes for it in its testsuite stages, read back through its
# writer's type map (libs/translator/writer/prim_writer.cpp: RGB is color3f, VECTOR vector3f,
# FLOAT float); Arnold User Guide, "Standard Surface" (Autodesk). arnold-usd writes every
# Arnold shader as a UsdShade shader with `info:id = "arnold:NODE"` and its parameters as
# `inputs:NAME` (libs/translator/writer/registry.cpp).
ARNOLD_STANDARD_SURFACE = dict(
    RGB=("base_color specular_color transmission_color transmission_scatter subsurface_color "
         "subsurface_radius sheen_color coat_color emission_color opacity"),
    FLOAT=("base diffuse_roughness metalness specular specular_roughness specular_IOR "
           "specular_anisotropy specular_rotation transmission transmission_depth "
           "transmission_scatter_anisotropy transmission_dispersion "
           "transmission_extra_roughness subsurface subsurface_scale subsurface_anisotropy "
           "sheen sheen_roughness coat coat_roughness coat_IOR coat_anisotropy coat_rotation "
           "coat_affect_color coat_affect_roughness thin_film_thickness thin_film_IOR emission "
           "indirect_diffuse indirect_specular"),
    VECTOR="normal tangent coat_normal",
    BOOLEAN="thin_walled caustics internal_reflections exit_to_background transmit_aovs",
)

# RenderMan's PxrSurface, its inputs' .args types. Pixar publishes no .args file outside
# RenderMan; sources: the RenderMan 23 plug-in parameter listing made from the .args files
# (nccastaff.bournemouth.ac.uk/jmacey/msc/renderman/links/plugins.23/: PxrLayerSurface, the
# global-parameter subset of PxrSurface, and PxrDiffuse), OpenUSD's hdPrman test stages
# (color3f diffuseColor, glowColor, specularFaceColor, specularEdgeColor; float
# specularRoughness, glowGain; `info:id = "PxrSurface"`, `token outputs:out`) and hdPrman's
# fallback material (float presence).
PXR_SURFACE = dict(
    color=("diffuseColor diffuseBackColor diffuseTransmitColor specularFaceColor "
           "specularEdgeColor specularIor specularExtinctionCoeff roughSpecularFaceColor "
           "roughSpecularEdgeColor roughSpecularIor roughSpecularExtinctionCoeff "
           "clearcoatFaceColor clearcoatEdgeColor clearcoatIor clearcoatExtinctionCoeff "
           "iridescencePrimaryColor iridescenceSecondaryColor fuzzColor subsurfaceColor "
           "subsurfaceDmfpColor shortSubsurfaceColor longSubsurfaceColor subsurfacePostTint "
           "singlescatterColor singlescatterMfpColor singlescatterDirectGainTint "
           "refractionColor glowColor"),
    float=("diffuseGain diffuseRoughness diffuseExponent diffuseTransmitGain "
           "specularFresnelShape specularRoughness specularAnisotropy roughSpecularRoughness "
           "roughSpecularAnisotropy clearcoatThickness clearcoatRoughness clearcoatAnisotropy "
           "iridescenceFaceGain iridescenceEdgeGain iridescenceRoughness iridescenceThickness "
           "fuzzGain fuzzConeAngle subsurfaceGain subsurfaceDmfp shortSubsurfaceDmfp "
           "longSubsurfaceDmfp subsurfaceDirectionality subsurfaceBleed singlescatterGain "
           "singlescatterMfp singlescatterDirectionality singlescatterIor singlescatterBlur "
           "refractionGain reflectionGain glassRoughness glassAnisotropy glassIor mwIor "
           "glowGain presence"),
    normal=("diffuseBumpNormal specularBumpNormal roughSpecularBumpNormal "
            "clearcoatBumpNormal iridescenceBumpNormal fuzzBumpNormal glassBumpNormal "
            "bumpNormal"),
    vector=("specularAnisotropyDirection roughSpecularAnisotropyDirection "
            "clearcoatAnisotropyDirection iridescenceAnisotropyDirection "
            "glassAnisotropyDirection"),
)


def table(source, model, types, files=()):
    """A definition from a table: each type's inputs as one space-separated string."""
    inputs = {name: t for t, names in types.items() for name in names.split()}
    inputs.update((f, "filename") for f in files)
    return dict(model=model, inputs=inputs, files=list(files), source=source)


# Texture readers: only their file inputs matter (the walk passes through any node that is no
# shading model). arnold:image reads `filename` (arnold-usd's UsdUVTexture translation,
# libs/common/materials_utils.cpp; its testsuite); RenderMan's readers: PxrTexture `filename`
# (RenderMan 20 documentation, "PxrTexture"), PxrMultiTexture `filename0`-`filename9`,
# PxrNormalMap and PxrBump `filename` (RenderMan documentation of each node).
ARNOLD = "Arnold's "
RENDERMAN = "RenderMan's "
TABLES = {
    "arnold:standard_surface": table(ARNOLD + "standard_surface", True, ARNOLD_STANDARD_SURFACE),
    "arnold:image": table(ARNOLD + "image", False, dict(STRING="color_space"),
                          files=("filename",)),
    "PxrSurface": table(RENDERMAN + "PxrSurface", True, PXR_SURFACE),
    "PxrTexture": table(RENDERMAN + "PxrTexture", False, dict(int="linearize"),
                        files=("filename",)),
    "PxrMultiTexture": table(RENDERMAN + "PxrMultiTexture", False, dict(int="linearize"),
                             files=tuple("filename%d" % k for k in range(10))),
    "PxrNormalMap": table(RENDERMAN + "PxrNormalMap", False, {}, files=("filename",)),
    "PxrBump": table(RENDERMAN + "PxrBump", False, {}, files=("filename",)),
}

# How a texture node is told to read the spectral file as written (linear reflectance, no
# decoding): (input, its USD type, value). UsdUVTexture: `sourceColorSpace` `raw` (the
# UsdPreviewSurface specification); PxrTexture: `linearize` 0, no reverse sRGB transform
# (RenderMan 20 documentation, "PxrTexture"); Arnold's image: `color_space` `Raw`, as
# arnold-usd's testsuite writes it (test_1209).
RAW_INPUTS = {
    "UsdUVTexture": ("sourceColorSpace", "token", "raw"),
    "PxrTexture": ("linearize", "int", 0),
    "PxrMultiTexture": ("linearize", "int", 0),
    "arnold:image": ("color_space", "string", "Raw"),
}


class Definitions:
    """Shader definitions, each looked up once; MaterialX's standard library is loaded the
    first time a MaterialX node is met."""

    def __init__(self):
        self.cache = {}
        self.lib = None

    def materialx(self):
        """The MaterialX module and its standard library, else (None, None)."""
        if self.lib is None:
            mx = mtlx_module()
            self.lib = (None, None)
            if mx is not None:
                lib = mx.createDocument()
                mx.loadLibraries(mx.getDefaultDataLibraryFolders(),
                                 mx.getDefaultDataSearchPath(), lib)
                self.lib = (mx, lib)
        return self.lib

    def of_id(self, sid):
        """The definition of a USD shader's `info:id`, else None."""
        if not sid:
            return None
        if sid not in self.cache:
            self.cache[sid] = TABLES.get(sid) or self.sdr(sid) or self.nodedef_named(sid)
        return self.cache[sid]

    def sdr(self, sid):
        try:
            from pxr import Sdr
        except ImportError:
            return None
        node = Sdr.Registry().GetShaderNodeByIdentifier(sid)
        if not node:
            return None
        inputs = {n: str(node.GetShaderInput(n).GetTypeAsSdfType().GetSdfType())
                  for n in node.GetShaderInputNames()}
        model = any(node.GetShaderOutput(o).GetType() == "terminal"
                    for o in node.GetShaderOutputNames())
        return dict(model=model, inputs=inputs,
                    files=[n for n, t in inputs.items() if t == "asset"],
                    source="usd-core's Sdr " + sid)

    def nodedef_named(self, sid):
        _, lib = self.materialx()
        nd = lib.getNodeDef(sid) if lib is not None else None
        return self.of_nodedef(nd, "MaterialX's") if nd else None

    def of_nodedef(self, nd, where):
        inputs = {i.getName(): i.getType() for i in nd.getActiveInputs()}
        return dict(model=nd.getType() in MX_MODEL_TYPES, inputs=inputs,
                    files=[n for n, t in inputs.items() if t == "filename"],
                    source="%s %s" % (where, nd.getName()))

    def of_mx_node(self, node):
        """The definition of a MaterialX document's node: the document's own nodedef for it,
        else the standard library's for its category and type (the default version)."""
        own = node.getNodeDef()
        if own is not None:
            return self.of_nodedef(own, "the document's")
        key = ("mx", node.getAttribute("nodedef"), node.getCategory(), node.getType())
        if key not in self.cache:
            _, lib = self.materialx()
            found = None
            if lib is not None:
                named = key[1] and lib.getNodeDef(key[1])
                matching = [nd for nd in lib.getMatchingNodeDefs(node.getCategory())
                            if nd.getType() == node.getType()]
                matching.sort(key=lambda nd: not nd.getDefaultVersion())
                nd = named or (matching[0] if matching else None)
                found = self.of_nodedef(nd, "MaterialX's") if nd else None
            self.cache[key] = found
        return self.cache[key]


DEFINITIONS = Definitions()


def typed(definition, name):
    """The use's `input_type` and `defined_by`: the input's type in the definition."""
    if definition is None or name not in definition["inputs"]:
        return dict(input_type=None, defined_by=None)
    return dict(input_type=definition["inputs"][name], defined_by=definition["source"])
