"""The MaterialX half of specconv's asset reader (docs/assets.md). The MaterialX package (PyPI
`MaterialX`) reads the document and its XIncludes; this module reports, in the form the USD half
(stage.py) gives, which image node feeds which input of which material through the graph, and
decides nothing.

Rules of MaterialX followed here: a filename is the element's active `fileprefix` followed by
its value, a relative result is found from the folder of the document given (MaterialX's
search path); the colour space is the file input's active `colorspace` (input, node, node
graph, document); a node's input connects by `nodename` (and `output`), `nodegraph` (and
`output`), or `interfacename` (an input of its node graph).
"""
import os
import stat

from .shader_defs import DEFINITIONS, mtlx_module, typed

# Nodes that take one channel out: the use is then that channel's (as a UsdUVTexture's r, g,
# b, a outputs are), so alpha to opacity stays alpha.
CHANNELS = "rgba"
SEPARATE = {"outr": "r", "outg": "g", "outb": "b", "outa": "a",
            "outx": "r", "outy": "g", "outz": "b", "outw": "a"}
MAX_INCLUDES = 1000
# Every document and XInclude loaded by the request being answered: files the output may never
# be (`read_files`); emptied at each request (the package answers many in one interpreter).
LOADED = []


class MtlxError(Exception):
    """A document that cannot be read: (kind, detail)."""


def regular(path, what):
    """Refuses anything but a regular file (a FIFO would block the reader, /dev/zero never
    ends) before MaterialX opens it."""
    try:
        mode = os.stat(path).st_mode
    except OSError as e:
        raise MtlxError("mtlx", "%s %s: %s" % (what, path, e.strerror))
    if not stat.S_ISREG(mode):
        raise MtlxError("mtlx", "%s %s is not a regular file (a FIFO, a device or a directory)"
                        % (what, path))


def load(mx, path):
    """The document at `path` with its XIncludes (MaterialX stops at a cycle); each include is
    checked to be a regular file first, and there are at most MAX_INCLUDES."""
    path = os.path.abspath(path)
    regular(path, "the MaterialX document")
    LOADED.append(path)
    count = [0]

    def include(doc, filename, search_path, options):
        found = search_path.find(filename)
        name = found.asString()
        LOADED.append(os.path.abspath(name))
        count[0] += 1
        if count[0] > MAX_INCLUDES:
            raise MtlxError("mtlx", "more than %d XIncludes" % MAX_INCLUDES)
        regular(name, "the XInclude")
        mx.readFromXmlFile(doc, found, search_path, options)

    options = mx.XmlReadOptions()
    options.readXIncludeFunction = include
    doc = mx.createDocument()
    try:
        mx.readFromXmlFile(doc, path, mx.FileSearchPath(os.path.dirname(path)), options)
    except MtlxError:
        raise
    except Exception as e:  # MaterialX's ExceptionParseError, ExceptionFileMissing
        raise MtlxError("mtlx", "MaterialX cannot read %s: %s" % (path, e))
    return doc


def connection(mx, doc, port):
    """The (node, output) an input or a node graph's output reads, else None."""
    scope = port.getParent()
    if port.isA(mx.Input) and isinstance(scope, mx.Node):
        scope = scope.getParent()
    graph_name = port.getAttribute("nodegraph")
    out_name = port.getAttribute("output")
    if graph_name:
        graph = doc.getNodeGraph(graph_name)
        if graph is None:
            return None
        outs = graph.getOutputs()
        out = graph.getOutput(out_name) if out_name else (outs[0] if len(outs) == 1 else None)
        return connection(mx, doc, out) if out is not None else None
    node_name = port.getAttribute("nodename")
    if node_name:
        node = scope.getChild(node_name) if scope is not None else None
        if node is None or not node.isA(mx.Node):
            return None
        return (node, out_name or "out")
    iface = port.getAttribute("interfacename")
    if iface and isinstance(scope, mx.NodeGraph):
        graph_input = scope.getInput(iface)
        return connection(mx, doc, graph_input) if graph_input is not None else None
    return None


def nodes_of(mx, doc):
    """Every node of the document and of its node graphs (not of definitions' graphs)."""
    found = list(doc.getNodes())
    for graph in doc.getNodeGraphs():
        if not graph.getNodeDefString():
            found.extend(graph.getNodes())
    return found


def file_input(node):
    """A texture node's filename input: `file`, else its only filename input."""
    inp = node.getInput("file")
    if inp is None:
        named = [i for i in node.getInputs() if i.getType() == "filename"]
        inp = named[0] if len(named) == 1 else None
    return inp


def through_interface(mx, inp):
    """The input that holds the value: a node graph's input where `inp` names one."""
    iface = inp.getAttribute("interfacename")
    graph = inp.getParent().getParent()
    if iface and isinstance(graph, mx.NodeGraph) and graph.getInput(iface) is not None:
        return graph.getInput(iface)
    return inp


def mtlx_file(mx, node, root_dir):
    """The texture's file: as written, resolved (fileprefix, from the document's folder),
    the active colorspace, and the document that wrote it."""
    inp = file_input(node)
    if inp is None:
        return None
    holder = through_interface(mx, inp)
    authored = holder.getValueString()
    if not authored:
        return dict(authored=None, resolved=None, colorspace=None, layer=None,
                    file_input=inp.getName())
    full = holder.getActiveFilePrefix() + authored
    anchored = os.path.normpath(os.path.join(root_dir, full))
    if "<UDIM>" in anchored.upper():
        resolved = anchored  # a pattern names no one file; the tiles are looked for later
    else:
        resolved = anchored if os.path.exists(anchored) else None
    source = holder.getActiveSourceUri() or None
    if source and not os.path.isabs(source):
        source = os.path.join(root_dir, source)
    # MaterialX manages the colour of colour images only: a float or vector image is read as
    # it is, whatever colour space it inherits.
    colour = node.getType() in ("color3", "color4", "multioutput")
    return dict(authored=authored, resolved=resolved, file_input=inp.getName(),
                colorspace=(holder.getActiveColorSpace() or None) if colour else None,
                layer=source, looked_for=anchored)


def channel_of(consumer, via, output):
    """The channel a use carries after `consumer` (reached through its input `via`, read on
    `output`): one of r g b a after an extraction node, else None."""
    category = consumer.getCategory()
    if category == "extract" and via == "in":
        index = consumer.getInput("index")
        try:
            k = int(index.getValueString()) if index is not None else 0
        except ValueError:
            return None
        return CHANNELS[k] if 0 <= k < 4 else None
    if category.startswith("separate"):
        return SEPARATE.get(output)
    if category == "swizzle":
        channels = consumer.getInput("channels")
        text = channels.getValueString() if channels is not None else ""
        if len(text) == 1 and text in "rgbaxyzw":
            return CHANNELS["rgbaxyzw".index(text) % 4]
    return None


def mtlx_network(mx, doc, material, wires):
    """The nodes a material reads, upstream of it, and the edges between them:
    (producer path, output) -> [(consumer, input name)]."""
    seen, todo, edges = set(), [material], {}
    while todo:
        node = todo.pop()
        path = node.getNamePath()
        if path in seen:
            continue
        seen.add(path)
        for inp in node.getInputs():
            source = wires.get((path, inp.getName()))
            if source is None:
                continue
            producer, output = source
            edges.setdefault((producer.getNamePath(), output), []).append((node, inp.getName()))
            todo.append(producer)
    return edges, seen


def mtlx_final_uses(edges, ports, start, max_depth):
    """The inputs the texture's output `start` feeds in the end (an input of a shading model,
    or of a node nothing reads on), each with its type in the node's definition and the
    channel an extraction on the way took."""
    uses, todo, seen = [], [(start, [], None)], set()
    while todo:
        port, through, channel = todo.pop()
        if (port, channel) in seen:
            continue
        if len(through) > max_depth:
            # The walk gives up here: said as a use of its own, so nothing is decided.
            uses.append(dict(shader=port[0], shader_id=None, input="", through=through,
                             channel=channel, cut=True))
            continue
        seen.add((port, channel))
        for consumer, name in edges.get(port, []):
            cpath = consumer.getNamePath()
            definition = DEFINITIONS.of_mx_node(consumer)
            model = definition is not None and definition["model"]
            onward = ports.get(cpath, []) if not model else []
            if not onward:
                uses.append(dict(shader=cpath, shader_id=consumer.getCategory(), input=name,
                                 through=through, channel=channel,
                                 inseparable=inseparable(consumer, name, through),
                                 **typed(definition, name)))
                continue
            for p in onward:
                took = channel or channel_of(consumer, name, p[1])
                todo.append((p, through + [cpath], took))
    return uses


def inseparable(consumer, name, through):
    """Why the copy of the document could not point this use at a copy of its image that
    keeps the original file (None: it can): only an input wired straight to the image, by
    `nodename` or a node graph's output, is re-pointed."""
    if through:
        return "it runs through %s" % ", ".join(through)
    inp = consumer.getInput(name)
    if inp is None or not (inp.getAttribute("nodename") or inp.getAttribute("nodegraph")):
        return "%s.%s reaches it through an interface input" % (consumer.getNamePath(), name)
    return None


def index_edges(edges):
    """The ports of each producer, so that the walk looks only at its own."""
    by_node = {}
    for port in edges:
        by_node.setdefault(port[0], []).append(port)
    return by_node


def mtlx_textures(mx, doc, root_dir, materials, max_depth, label):
    """Texture nodes (the form stage.py gives) that `materials` (name -> (node, the
    material's name in the uses)) read."""
    all_nodes = nodes_of(mx, doc)
    wires = {}
    for node in all_nodes:
        for inp in node.getInputs():
            source = connection(mx, doc, inp)
            if source is not None:
                wires[(node.getNamePath(), inp.getName())] = source
    by_path = {node.getNamePath(): node for node in all_nodes}
    textures = []
    for _, (material, mname) in sorted(materials.items()):
        edges, network = mtlx_network(mx, doc, material, wires)
        ports = index_edges(edges)
        for path in sorted(network):
            node = by_path.get(path)
            definition = DEFINITIONS.of_mx_node(node) if node is not None else None
            if definition is None or not definition["files"]:
                continue
            f = mtlx_file(mx, node, root_dir)
            if f is None:
                continue
            uses = []
            for port in ports.get(path, []):
                for use in mtlx_final_uses(edges, ports, port, max_depth):
                    channel = use.pop("channel")
                    uses.append(dict(use, material=mname, output=channel or port[1]))
            scs = node.getInput("sourceColorSpace")
            textures.append(dict(
                node=path, node_id="ND_%s_%s" % (node.getCategory(), node.getType()),
                source_color_space=(scs.getValueString() or None) if scs is not None else None,
                package=None, uses=uses, document=label, **f))
    return textures


def materials_of(mx, doc):
    """Every material node of the document, by name."""
    return {n.getNamePath(): (n, n.getNamePath()) for n in doc.getNodes()
            if n.getType() == "material"}


def read_document(path, max_depth):
    """`read` of a MaterialX document: every material node in it is read."""
    mx = mtlx_module()
    path = os.path.abspath(path)
    doc = load(mx, path)
    materials = materials_of(mx, doc)
    textures = mtlx_textures(mx, doc, os.path.dirname(path), materials, max_depth, path)
    return dict(stage=path, materials=len(materials), bound_prims=0, composition_errors=[],
                textures=textures, references=[], read_files=sorted(set(LOADED)))


def flatten_files(mx, doc, root_dir):
    """Every filename made absolute as `mtlx_file` resolves it, and no fileprefix left: the
    copy is read from another folder than the original."""
    for elem in doc.traverseTree():
        if elem.isA(mx.ValueElement) and elem.getType() == "filename" \
                and elem.getValueString():
            full = elem.getActiveFilePrefix() + elem.getValueString()
            elem.setValueString(os.path.normpath(os.path.join(root_dir, full)))
    for elem in doc.traverseTree():
        if elem.hasFilePrefix():
            elem.removeAttribute("fileprefix")
    if doc.hasFilePrefix():
        doc.removeAttribute("fileprefix")


def keep_original(mx, doc, node, keep):
    """The data uses `keep` (shader, input) of the image `node`, which is about to read its
    spectral file, pointed at a copy of it that keeps the original file: `NAME_original`
    beside it, reached by `nodename` or by a new output `OUT_original` of its node graph (the
    reader only lets a use through that is wired so, `inseparable`)."""
    if not keep:
        return
    parent = node.getParent()
    name = parent.createValidChildName(node.getName() + "_original")
    copy = parent.addNode(node.getCategory(), name, node.getType())
    copy.copyContentFrom(node)
    for k in keep:
        shader = doc.getDescendant(k["shader"])
        inp = shader.getInput(k["input"]) if shader is not None else None
        if inp is None:
            raise MtlxError("mtlx", "no input %s.%s to keep" % (k["shader"], k["input"]))
        if inp.getAttribute("nodename"):
            inp.setNodeName(name)
            continue
        graph = doc.getNodeGraph(inp.getAttribute("nodegraph"))
        outs = graph.getOutputs()
        out = graph.getOutput(inp.getOutputString()) if inp.getOutputString() else outs[0]
        kept = graph.getOutput(out.getName() + "_original") or \
            graph.addOutput(graph.createValidChildName(out.getName() + "_original"),
                            out.getType())
        kept.setNodeName(name)
        inp.setOutputString(kept.getName())


def document_text(source, overrides):
    """The override document of `source`: a copy, XIncludes written in, every filename
    absolute, and each override's file input pointed at its spectral file (relative to the
    copy), read in the document's working colour space (no conversion: the spectra are
    linear), the original value and colour space kept as `specconv_original*` attributes."""
    mx = mtlx_module()
    doc = load(mx, source)
    working = doc.getColorSpace() or "lin_rec709"
    flatten_files(mx, doc, os.path.dirname(os.path.abspath(source)))
    doc.setAttribute("specconv_source", os.path.abspath(source))
    for o in overrides:
        node = doc.getDescendant(o["node"])
        inp = file_input(node) if node is not None and node.isA(mx.Node) else None
        if inp is None:
            raise MtlxError("mtlx", "%s has no node %s with a file input" % (source, o["node"]))
        keep_original(mx, doc, node, o.get("keep", []))
        if inp.hasAttribute("interfacename"):
            inp.removeAttribute("interfacename")
        inp.setValueString(o["file"])
        inp.setAttribute("specconv_original", o.get("original") or "")
        if o.get("original_colorspace"):
            inp.setAttribute("specconv_original_colorspace", o["original_colorspace"])
        inp.setColorSpace(working)
        if node.getCategory() == "UsdUVTexture":
            scs = node.getInput("sourceColorSpace") or node.addInput("sourceColorSpace",
                                                                       "string")
            scs.setValueString("raw")
    options = mx.XmlWriteOptions()
    options.writeXIncludeEnable = False
    return mx.writeToXmlString(doc, options)
