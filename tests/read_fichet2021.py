"""Reads a spectral OpenEXR with colour-science's reference reader for the Fichet et al. 2021
layout and prints what it sees as JSON: per component (T, or S0 for emission), the wavelengths,
the image shape and the spectrum of pixel (x, y) given on the command line; under "spec",
whether the reader takes the file as emissive and the header's string attributes (among them
emissiveUnits)."""
import json
import sys
import warnings

warnings.simplefilter("ignore")
import colour  # noqa: E402

path, x, y = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
components, spec = colour.io.read_spectral_image_Fichet2021(path, additional_data=True)
out = {}
for name, (wavelengths, image) in components.items():
    out[name] = {
        "wavelengths": [float(w) for w in wavelengths],
        "shape": list(image.shape),
        "pixel": [float(v) for v in image[y, x]],
    }
out["spec"] = {
    "emissive": bool(spec.is_emissive),
    "attributes": {a.name: a.value for a in spec.attributes if isinstance(a.value, str)},
}
print(json.dumps(out))
