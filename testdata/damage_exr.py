"""Damages a valid single-part OpenEXR file the ways real files break, for the error tests.

  damage_exr.py window  IN OUT X0 Y0 X1 Y1   sets dataWindow (and displayWindow) to (X0 Y0)-(X1 Y1):
                                            a header that promises more than the file holds
  damage_exr.py garble  IN OUT               overwrites the data of the first chunk with 0xff:
                                            a first block that cannot be decoded
  damage_exr.py cut     IN OUT FRACTION      keeps the header, the offset table and FRACTION of
                                            the chunks' bytes: a file truncated while written

The header is a list of attributes (name NUL, type NUL, int32 size, value) ending in a NUL byte,
after the 8-byte magic number and version (openexr.com, "OpenEXR File Layout").
"""
import struct
import sys


def attributes(data):
    """Yields (name, type, value offset, size) of each header attribute; returns the header end."""
    pos = 8
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        (size,) = struct.unpack_from("<i", data, type_end + 1)
        yield data[pos:name_end].decode(), data[name_end + 1 : type_end].decode(), type_end + 5, size
        pos = type_end + 5 + size


def header_end(data):
    *_, (name, _, value, size) = attributes(data)
    return value + size + 1


def main():
    what, src, dst = sys.argv[1:4]
    data = bytearray(open(src, "rb").read())
    if what == "window":
        box = struct.pack("<4i", *map(int, sys.argv[4:8]))
        for name, _, value, size in attributes(data):
            if name in ("dataWindow", "displayWindow"):
                data[value : value + size] = box
    elif what == "garble":
        (first,) = struct.unpack_from("<Q", data, header_end(data))
        # Chunk: int32 y, int32 size, then the data.
        (size,) = struct.unpack_from("<i", data, first + 4)
        data[first + 8 : first + 8 + size] = b"\xff" * size
    elif what == "cut":
        (first,) = struct.unpack_from("<Q", data, header_end(data))
        data = data[: first + int((len(data) - first) * float(sys.argv[4]))]
    else:
        sys.exit(__doc__)
    open(dst, "wb").write(data)


main()
