"""Between QGIS features and the skeletonise wheel (``skeletonise._core``).

Geometries cross as WKB (``QgsGeometry.asWkb``); the work runs in Rust with
the GIL released, in batches of about ``BATCH_VERTICES`` vertices so that
progress moves and a cancel is seen between batches, and within one (a cancel
flag the Rust loop checks, where the wheel has it). Results come back as WKB
and column buffers and become the sink's features here. No GDAL and no
pandas: QGIS's own numpy is all the wheel needs.
"""

import json
import math
import os
import threading

import numpy as np
from qgis.core import (
    QgsFeature,
    QgsFeatureRequest,
    QgsFeatureSink,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsProcessingException,
    QgsProcessingFeatureSource,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QVariant

from . import bundle

# The work of one call into Rust: enough for the threads to share (a batch of
# small lakes), small enough that progress moves and a cancel between batches
# is seen in well under a second on a laptop.
BATCH_VERTICES = 100_000
BATCH_FEATURES = 2_000

_TYPES = {"int32": QVariant.Int, "int64": QVariant.LongLong, "real": QVariant.Double, "text": QVariant.String}


def core():
    """The wheel's Rust module (the plugin's bundled copy where it runs, else an installed one),
    or a Processing error saying what to install."""
    bundle.activate()
    try:
        from skeletonise import _core
    except ImportError as e:
        raise QgsProcessingException(
            f"The skeletonise Python package could not be imported ({e}). {install_hint()}"
        ) from None
    return _core


def install_hint():
    """What to install on this platform, with the exact command (bundle.install_hint)."""
    hint = bundle.install_hint()
    return hint[:1].upper() + hint[1:] + "."


def version():
    """The wheel's version, or None when it is not there."""
    try:
        return core().__version__
    except QgsProcessingException:
        return None


def bundled():
    """Whether the `skeletonise` in use is the plugin's bundled copy."""
    if version() is None:
        return False
    import skeletonise

    return os.path.abspath(skeletonise.__file__).startswith(bundle.FOLDER + os.sep)


def check_crs(crs, name):
    """What the command line refuses before any work: a geographic CRS (radii and scores would be in degrees)."""
    if crs.isValid() and crs.isGeographic():
        raise QgsProcessingException(
            f"layer `{name}` has the geographic CRS {crs.authid() or crs.description()}; skeleton radii and "
            "scores need a projected CRS: reproject it first (Processing ▸ Vector general ▸ Reproject layer, "
            "native:reprojectlayer), e.g. to the UTM zone or an equal-area CRS of the region"
        )


def layer_name(layer, source):
    """The name the command line gives a layer: a file's layer name (``layername=`` of the
    source), else the QGIS layer's name, else the source's."""
    if layer is not None:
        from qgis.core import QgsProviderRegistry

        parts = QgsProviderRegistry.instance().decodeUri(layer.providerType(), layer.source())
        return parts.get("layerName") or layer.name()
    return source.sourceName()


class Features:
    """The features of a source as the wheel takes them: FIDs, attributes, WKB."""

    def __init__(self):
        self.fids = []
        self.attributes = []
        self.wkbs = []
        self.repaired = []
        self.vertices = []

    def __len__(self):
        return len(self.fids)


def read(source, make_valid, feedback, share=10.0):
    """Every feature of ``source`` (a QgsProcessingFeatureSource): invalid
    polygons repaired by QGIS's makeValid (the algorithm GEOS MakeValid, which
    the command line's reader uses, also comes from; on a repaired polygon the
    two may differ in detail) when the
    pipeline's ``prepare.make_valid`` is on; curves segmentised; Z and M
    dropped by the reader in Rust. Progress runs to ``share`` percent.
    With ``make_valid`` on, QGIS's own invalid-geometry check (the
    Processing setting, which stops the algorithm at an invalid polygon or
    skips it by default) is left out: the polygon is repaired here, as the
    command line repairs it."""
    out = Features()
    total = source.featureCount() or 1
    flags = QgsProcessingFeatureSource.FlagSkipGeometryValidityChecks if make_valid else QgsProcessingFeatureSource.Flags()
    for i, f in enumerate(source.getFeatures(QgsFeatureRequest(), flags)):
        if feedback.isCanceled():
            break
        out.fids.append(int(f.id()))
        out.attributes.append(f.attributes())
        wkb, repaired, n = None, False, 0
        if f.hasGeometry():
            g = f.geometry()
            if QgsWkbTypes.isCurvedType(g.wkbType()):
                g = QgsGeometry(g.constGet().segmentize())
            if make_valid and not g.isGeosValid():
                fixed = g.makeValid()
                if not fixed.isNull():
                    g, repaired = fixed, True
            n = g.constGet().nCoordinates()
            wkb = bytes(g.asWkb())
        out.wkbs.append(wkb)
        out.repaired.append(repaired)
        out.vertices.append(n)
        if i % 1000 == 0:
            feedback.setProgress(share * i / total)
    return out


def batches(features):
    """Ranges of features for one call each: about BATCH_VERTICES vertices or BATCH_FEATURES features."""
    start, vertices = 0, 0
    for i, n in enumerate(features.vertices):
        if i > start and (vertices + n > BATCH_VERTICES or i - start >= BATCH_FEATURES):
            yield start, i
            start, vertices = i, 0
        vertices += n
    if start < len(features):
        yield start, len(features)


def source_fields(fields, skip):
    """The source's fields to carry (not those in ``skip``, the GeoPackage's FID column)."""
    return [i for i in range(fields.count()) if fields.at(i).name() not in skip]


def output_fields(fields, carried, tool_columns, rejected=True, reserved=()):
    """The sink's fields: the carried source fields (``src_<name>``, the
    prefix repeated until the name is free, where a name is one of the
    tool's or of ``reserved``, as the command line's writer renames them),
    the tool's columns, then ``rejected``."""
    out = QgsFields()
    taken = [name for name, _ in tool_columns] + list(reserved) + ["rejected"]
    names = core().source_names([fields.at(i).name() for i in carried], taken)
    for i, name in zip(carried, names):
        f = QgsField(fields.at(i))
        f.setName(name)
        out.append(f)
    for name, kind in tool_columns:
        out.append(QgsField(name, _TYPES[kind]))
    if rejected:
        out.append(QgsField("rejected", QVariant.String))
    return out


def _texts(offsets, data, null):
    n = len(offsets) - 1
    if null is True:
        return [None] * n
    return [
        None if null is not None and null[i] else data[offsets[i] : offsets[i + 1]].decode() for i in range(n)
    ]


def columns(done):
    """The columns of a ``Pipeline.run`` result as Python lists (NULL as None)."""
    reals = done["reals"]
    out = []
    for _name, kind, values in done["columns"]:
        if kind in ("int32", "int64"):
            v, null = values
            out.append([None if m else int(x) for x, m in zip(v.tolist(), null.tolist())])
        elif kind == "real":
            out.append([None if math.isnan(x) else x for x in reals[values].tolist()])
        else:
            out.append(_texts(*values))
    if "rejected" in done:
        out.append(_texts(*done["rejected"]))
    return out


def geometry(wkb):
    """A QgsGeometry from WKB (an empty one for NULL)."""
    g = QgsGeometry()
    if wkb is not None:
        g.fromWkb(wkb)
    return g


class Cancelled(Exception):
    """The user cancelled: the batch in progress stopped before its next feature."""


def cancellable(feedback, call, *args, **kwargs):
    """``call(*args, cancel=flag, **kwargs)`` in a thread of its own (Rust
    releases the GIL), while this one watches ``feedback`` every 20 ms and sets
    the wheel's cancel flag once the user cancels: the call then stops before
    its next feature and :class:`Cancelled` is raised here."""
    core_ = core()
    flag = core_.Cancel()
    out = {}

    def work():
        try:
            out["done"] = call(*args, cancel=flag, **kwargs)
        except BaseException as e:  # noqa: BLE001 - handed to the caller's thread
            out["error"] = e

    t = threading.Thread(target=work, name="skeletonise", daemon=True)
    t.start()
    while t.is_alive():
        t.join(0.02)
        if feedback.isCanceled() and not flag.is_set():
            flag.set()
    if isinstance(out.get("error"), core_.Cancelled):
        raise Cancelled()
    if "error" in out:
        raise out["error"]
    return out["done"]


def run_pipeline(pipeline, features, batch, feedback, *, candidates, explode=None, **extra):
    """One batch through ``Pipeline.run``, cancellable: the result's rows
    (input positions within the batch), columns and WKB geometries."""
    start, end = batch
    return cancellable(
        feedback,
        pipeline.run,
        features.wkbs[start:end],
        fids=np.asarray(features.fids[start:end], dtype=np.int64),
        repaired=np.asarray(features.repaired[start:end], dtype=bool),
        candidates=candidates,
        explode=explode,
        output="wkb",
        **extra,
    )


def write(sink, done, features, start, carried, feedback):
    """The rows of ``done`` as features of ``sink``; a rejected feature is
    reported through ``feedback.reportError`` (its row is kept: NULL
    geometry, the reason in ``rejected``). Returns the number rejected."""
    cols = columns(done)
    rows = done["row"].tolist()
    wkbs = done["geometry"][1]
    reasons = cols[-1] if "rejected" in done else [None] * len(rows)
    rejected = 0
    for k, r in enumerate(rows):
        i = start + r
        attrs = [features.attributes[i][j] for j in carried]
        attrs.extend(c[k] for c in cols)
        f = QgsFeature()
        f.setAttributes(attrs)
        if wkbs[k] is not None:
            f.setGeometry(geometry(wkbs[k]))
        if not sink.addFeature(f, QgsFeatureSink.FastInsert):
            raise QgsProcessingException(f"could not write a feature of FID {features.fids[i]} to the output")
        if reasons[k] is not None:
            rejected += 1
            feedback.reportError(f"feature {features.fids[i]} rejected: {reasons[k]}")
    return rejected


def write_layer(sink, layer, attributes, carried):
    """The rows of a layer beside the skeletons (``layers`` of a result) as
    features of ``sink``: the source's fields of each row found by its
    ``src_fid`` through ``attributes(fid)`` (a list, or None)."""
    cols = columns(layer)
    names = [name for name, _kind, _values in layer["columns"]]
    fid_column = cols[names.index("src_fid")] if "src_fid" in names else None
    for k, wkb in enumerate(layer["geometry"][1]):
        source = attributes(fid_column[k]) if fid_column is not None and carried else None
        attrs = [source[j] if source is not None else None for j in carried]
        attrs.extend(c[k] for c in cols)
        f = QgsFeature()
        f.setAttributes(attrs)
        if wkb is not None:
            f.setGeometry(geometry(wkb))
        if not sink.addFeature(f, QgsFeatureSink.FastInsert):
            raise QgsProcessingException("could not write a feature to the output")


def options_pipeline(doc, origin):
    """A pipeline from a steps document (the pipeline file's keys)."""
    try:
        return core().Pipeline.from_options(json.dumps(doc), origin)
    except core().PipelineError as e:
        raise QgsProcessingException(str(e)) from None
