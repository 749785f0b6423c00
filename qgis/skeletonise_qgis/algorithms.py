"""The Processing algorithms of the `skeletonise` provider.

Each runs the command line's per-feature path in-process (the skeletonise
wheel); option names and defaults are the pipeline file's. Features read are
all written: a feature that cannot be processed gets a row with a NULL
geometry and its reason in ``rejected``, and the reason is reported through
the feedback.
"""

import json
import os

from qgis.core import (
    QgsFeature,
    QgsFeatureSink,
    QgsProcessing,
    QgsProcessingAlgorithm,
    QgsProcessingException,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFeatureSource,
    QgsProcessingParameterFile,
    QgsProcessingParameterNumber,
    QgsProcessingParameterString,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QCoreApplication
from qgis.PyQt.QtGui import QIcon

from . import bridge

METHODS = ["MA", "StSk", "DVD", "CDT", "VD"]
PRUNE = ["significance", "length", "trunk", "none"]
EXTEND = ["centred", "ray", "nearest", "none"]
SELECT = ["distortion", "deviation", "deviation_parts", "distortion_sum"]
PARTS = ["each", "largest"]

HELP_URL = "https://github.com/skeletonise/skeletonise#in-qgis"


def _tr(text):
    return QCoreApplication.translate("skeletonise", text)


class _Algorithm(QgsProcessingAlgorithm):
    """What every algorithm of the provider shares."""

    NAME = ""
    DISPLAY = ""
    HELP = ""

    def createInstance(self):  # noqa: N802
        return type(self)()

    def name(self):
        return self.NAME

    def displayName(self):  # noqa: N802
        return _tr(self.DISPLAY)

    def group(self):
        return _tr("Skeletons")

    def groupId(self):  # noqa: N802
        return "skeletons"

    def shortHelpString(self):  # noqa: N802
        return _tr(self.HELP)

    def helpUrl(self):  # noqa: N802
        return HELP_URL

    def icon(self):
        return QIcon(os.path.join(os.path.dirname(__file__), "icon.svg"))

    def canExecute(self):  # noqa: N802
        if bridge.version() is None:
            return False, f"The skeletonise Python package is missing: {bridge.INSTALL_HINT}."
        return True, ""

    # --- shared steps -------------------------------------------------------

    def _input(self, parameters, context):
        source = self.parameterAsSource(parameters, "INPUT", context)
        if source is None:
            raise QgsProcessingException(self.invalidSourceError(parameters, "INPUT"))
        layer = self.parameterAsVectorLayer(parameters, "INPUT", context)
        name = layer.name() if layer is not None else source.sourceName()
        bridge.check_crs(source.sourceCrs(), name)
        # A GeoPackage's FID column shows as a field in QGIS: the command line
        # never carries it (src_fid holds it), and a copy would clash with the
        # output's own FIDs.
        skip = set()
        if layer is not None:
            fields = layer.fields()
            skip = {fields.at(i).name() for i in layer.dataProvider().pkAttributeIndexes()}
        return source, skip

    def _pipeline_rows(self, pipeline, parameters, context, feedback, explode):
        """Runs ``pipeline`` on INPUT, writing OUTPUT (and CANDIDATES when given)."""
        source, skip = self._input(parameters, context)
        features = bridge.read(source, pipeline.make_valid, feedback)
        carried = bridge.source_fields(source.fields(), skip) if core_columns("skeletons", explode)[1] else []
        results = {}
        sinks = [("OUTPUT", False)]
        if parameters.get("CANDIDATES") is not None and "CANDIDATES" in [p.name() for p in self.parameterDefinitions()]:
            sinks.append(("CANDIDATES", True))
        outputs = {}
        for key, candidates in sinks:
            tool, carries = core_columns("candidates" if candidates else "skeletons", explode)
            fields = bridge.output_fields(source.fields(), carried if carries else [], tool)
            sink, dest = self.parameterAsSink(
                parameters, key, context, fields, QgsWkbTypes.MultiLineString, source.sourceCrs()
            )
            if sink is None and key == "OUTPUT":
                raise QgsProcessingException(self.invalidSinkError(parameters, key))
            if sink is not None:
                outputs[key] = (sink, candidates, carried if carries else [])
                results[key] = dest
        counts = {"read": len(features), "written": 0, "rejected": 0}
        parts = list(bridge.batches(features))
        for k, (start, end) in enumerate(parts):
            done_all = {}
            try:
                for key, (_sink, candidates, _carried) in outputs.items():
                    done_all[key] = bridge.run_pipeline(
                        pipeline, features, (start, end), feedback, candidates=candidates, explode=explode
                    )
            except bridge.Cancelled:
                feedback.pushInfo(f"cancelled: the first {start} of {len(features)} features are written")
                break
            except bridge.core().RejectedError as e:
                raise QgsProcessingException(str(e)) from None
            for key, (sink, candidates, carried_here) in outputs.items():
                done = done_all[key]
                rejected = bridge.write(
                    sink, done, features, start, carried_here, feedback if not candidates else _Quiet()
                )
                if not candidates:
                    counts["written"] += done["counts"]["written"]
                    counts["rejected"] += rejected
            feedback.setProgress(10 + 90 * (k + 1) / len(parts))
        feedback.pushInfo(
            f"{counts['read']} features read, {counts['written']} written, {counts['rejected']} rejected"
        )
        results["FEATURES_READ"] = counts["read"]
        results["FEATURES_REJECTED"] = counts["rejected"]
        return results


class _Quiet:
    """Feedback for the candidates' pass: the rejections were reported with the skeletons."""

    def reportError(self, *_args):  # noqa: N802
        pass


def core_columns(layer, explode):
    """The tool's columns of ``layer`` and whether it carries the source's fields."""
    return bridge.core().columns(layer, explode)


def _sinks(alg, candidates=True):
    alg.addParameter(
        QgsProcessingParameterFeatureSink(
            "OUTPUT", _tr("Skeletons"), QgsProcessing.TypeVectorLine
        )
    )
    if candidates:
        alg.addParameter(
            QgsProcessingParameterFeatureSink(
                "CANDIDATES",
                _tr("Candidates (every method's skeleton and scores)"),
                QgsProcessing.TypeVectorLine,
                optional=True,
                createByDefault=False,
            )
        )


def _polygons(alg):
    alg.addParameter(
        QgsProcessingParameterFeatureSource(
            "INPUT", _tr("Polygons (a projected CRS)"), [QgsProcessing.TypeVectorPolygon]
        )
    )


class SkeletoniseAlgorithm(_Algorithm):
    """Polygons → skeletons: every method, pruned, extended, scored, the best one chosen."""

    NAME = "skeletonise"
    DISPLAY = "Skeletonise polygons"
    HELP = (
        "Collapses every polygon to its skeleton (centreline) with the chosen methods — Voronoi diagram "
        "of the vertices (VD), densified Voronoi (DVD), constrained Delaunay triangulation (CDT), straight "
        "skeleton (StSk), medial axis (MA) — prunes the short legs, extends the kept ones to the boundary, "
        "scores each method with the deviation and distortion metrics of Szombara's comparison of "
        "skeletonisation methods and keeps the best one per feature, as the command line's default "
        "pipeline (`skeletonise run -i SRC -o OUT.gpkg`) does.\n\n"
        "<b>Polygons</b>: a polygon layer in a projected CRS (radii and scores are in its units); "
        "a geographic layer is refused: reproject it first.\n"
        "<b>Methods</b>: the methods to run (default all five); the medial axis is computed for the "
        "shared leg structure whether or not it is chosen.\n"
        "<b>Prune</b>: significance (default: legs that protrude beyond the inscribed disc at their "
        "junction, and arms), length (legs shorter than the minimum length only), trunk (the longest "
        "path only: one centreline per polygon), none (every leg).\n"
        "<b>Minimum leg length</b>: legs shorter than this (layer units) are removed; 0: none.\n"
        "<b>Extend</b>: centred (default: along the method's own removed legs to the boundary), ray (the "
        "leg's direction to the boundary), nearest (to the nearest boundary point), none.\n"
        "<b>Select by</b>: the metric by which the best method is chosen (smaller is better): distortion "
        "Z (default), deviation s, deviation_parts S, distortion_sum SZ.\n"
        "<b>One row per polygon part</b>: a multipolygon gives a row per part (polygon_part).\n"
        "<b>Skeletons</b>: one row per feature: the source's fields, src_fid (the source FID), method, "
        "the scores and counts, and rejected (why a feature has no skeleton; it is also reported in the "
        "log).\n"
        "<b>Candidates</b>: optional; every method's row with its scores, chosen and error."
    )

    def initAlgorithm(self, config=None):  # noqa: N802
        _polygons(self)
        self.addParameter(
            QgsProcessingParameterEnum(
                "METHODS", _tr("Methods"), options=METHODS, allowMultiple=True, defaultValue=list(range(len(METHODS)))
            )
        )
        self.addParameter(QgsProcessingParameterEnum("PRUNE", _tr("Prune"), options=PRUNE, defaultValue=0))
        self.addParameter(
            QgsProcessingParameterNumber(
                "MIN_LENGTH",
                _tr("Minimum leg length (layer units; 0: none)"),
                QgsProcessingParameterNumber.Double,
                defaultValue=0.0,
                minValue=0.0,
            )
        )
        self.addParameter(QgsProcessingParameterEnum("EXTEND", _tr("Extend"), options=EXTEND, defaultValue=0))
        self.addParameter(QgsProcessingParameterEnum("SELECT", _tr("Select by"), options=SELECT, defaultValue=0))
        self.addParameter(QgsProcessingParameterBoolean("EXPLODE", _tr("One row per polygon part"), defaultValue=False))
        _sinks(self)

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        methods = [METHODS[i] for i in self.parameterAsEnums(parameters, "METHODS", context)]
        if not methods:
            raise QgsProcessingException("`methods`: choose at least one method")
        prune = {"mode": PRUNE[self.parameterAsEnum(parameters, "PRUNE", context)]}
        min_length = self.parameterAsDouble(parameters, "MIN_LENGTH", context)
        if min_length > 0:
            prune["min_length"] = min_length
        doc = {
            "steps": [
                {"prepare": {}},
                {"skeleton": {"methods": methods}},
                {"prune": prune},
                {"extend": {"mode": EXTEND[self.parameterAsEnum(parameters, "EXTEND", context)]}},
                {"score": {}},
                {"select": {"by": SELECT[self.parameterAsEnum(parameters, "SELECT", context)]}},
            ]
        }
        pipeline = bridge.options_pipeline(doc, "skeletonise:skeletonise")
        explode = self.parameterAsBoolean(parameters, "EXPLODE", context)
        return self._pipeline_rows(pipeline, parameters, context, feedback, explode)


class PipelineAlgorithm(_Algorithm):
    """A pipeline file's steps on a layer (the Python package's ``apply``)."""

    NAME = "pipeline"
    DISPLAY = "Run a pipeline file"
    HELP = (
        "Runs the steps of a skeletonise pipeline file (YAML) on a polygon layer: the same file as "
        "`skeletonise run FILE.yaml` takes; its input and output sections are not used (the layers of "
        "this dialog are), except output.explode and on_error. The collapse and partition steps, which "
        "write layers of their own, run from the command line only.\n\n"
        "<b>Pipeline file</b>: the YAML file; it is validated as `skeletonise validate` does, with the "
        "same messages.\n"
        "<b>Overrides</b>: optional KEY=VALUE settings, as the command line's --set, separated by "
        "semicolons or new lines, e.g. steps.skeleton.methods=[MA]; steps.prune.mode=trunk.\n"
        "<b>Skeletons</b>, <b>Candidates</b>: as in Skeletonise polygons."
    )

    def initAlgorithm(self, config=None):  # noqa: N802
        _polygons(self)
        self.addParameter(
            QgsProcessingParameterFile(
                "PIPELINE", _tr("Pipeline file"), behavior=QgsProcessingParameterFile.File, fileFilter="YAML (*.yaml *.yml)"
            )
        )
        self.addParameter(
            QgsProcessingParameterString("OVERRIDES", _tr("Overrides (KEY=VALUE; …)"), optional=True, multiLine=True)
        )
        _sinks(self)

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        path = self.parameterAsFile(parameters, "PIPELINE", context)
        text = self.parameterAsString(parameters, "OVERRIDES", context) or ""
        overrides = [s.strip() for s in text.replace("\n", ";").split(";") if s.strip()]
        core = bridge.core()
        try:
            pipeline = core.Pipeline.load(path, overrides)
        except (core.PipelineError, OSError) as e:
            raise QgsProcessingException(str(e)) from None
        return self._pipeline_rows(pipeline, parameters, context, feedback, pipeline.explode)


class LabelAlgorithm(_Algorithm):
    """One label line (or point) per polygon part, for curved labels."""

    NAME = "label"
    DISPLAY = "Label lines"
    HELP = (
        "One label per polygon part, as the command line's label step: a smooth line along the medial "
        "axis where the part is elongated enough to carry a curved name, otherwise the centre of its "
        "largest inscribed disc (the pole of inaccessibility). Holes (islands) are respected.\n\n"
        "<b>Polygons</b>: a polygon layer in a projected CRS.\n"
        "<b>Smooth</b>: the most the line may turn (degrees) over any stretch one local width long.\n"
        "<b>Margin</b>: how close to the axis the line stays, as a fraction of the local radius (0.9: "
        "within a tenth of the radius of the axis).\n"
        "<b>Minimum elongation</b>: a line where its length is at least this many times the largest "
        "width, else a point.\n"
        "<b>Parts</b>: each (a label per polygon part) or largest (one per feature).\n"
        "<b>Minimum pixels</b>: minzoom is the smallest web-map zoom at which the line is this many "
        "pixels long (a point's disc this wide) at its latitude.\n"
        "<b>Labels</b>: the source's fields, src_fid, polygon_part, kind (line, point), length, "
        "max_width, elongation, minzoom, rejected."
    )

    def initAlgorithm(self, config=None):  # noqa: N802
        _polygons(self)
        number = QgsProcessingParameterNumber.Double
        self.addParameter(QgsProcessingParameterNumber("SMOOTH", _tr("Smooth (degrees)"), number, 60.0, minValue=1.0, maxValue=180.0))
        self.addParameter(QgsProcessingParameterNumber("MARGIN", _tr("Margin (fraction of the local radius)"), number, 0.9, minValue=0.0, maxValue=1.0))
        self.addParameter(QgsProcessingParameterNumber("MIN_ELONGATION", _tr("Minimum elongation"), number, 3.0, minValue=0.0))
        self.addParameter(QgsProcessingParameterEnum("PARTS", _tr("Parts"), options=PARTS, defaultValue=0))
        self.addParameter(QgsProcessingParameterNumber("MIN_PIXELS", _tr("Minimum pixels (for minzoom)"), number, 64.0, minValue=0.0))
        self.addParameter(QgsProcessingParameterFeatureSink("OUTPUT", _tr("Labels"), QgsProcessing.TypeVectorAnyGeometry))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        source, skip = self._input(parameters, context)
        options = {
            "smooth": self.parameterAsDouble(parameters, "SMOOTH", context),
            "margin": self.parameterAsDouble(parameters, "MARGIN", context),
            "min_elongation": self.parameterAsDouble(parameters, "MIN_ELONGATION", context),
            "parts": PARTS[self.parameterAsEnum(parameters, "PARTS", context)],
            "min_pixels": self.parameterAsDouble(parameters, "MIN_PIXELS", context),
        }
        features = bridge.read(source, True, feedback)
        carried = bridge.source_fields(source.fields(), skip)
        tool = [
            ("src_fid", "int64"),
            ("polygon_part", "int32"),
            ("kind", "text"),
            ("length", "real"),
            ("max_width", "real"),
            ("elongation", "real"),
            ("minzoom", "int32"),
        ]
        fields = bridge.output_fields(source.fields(), carried, tool)
        crs = source.sourceCrs()
        sink, dest = self.parameterAsSink(parameters, "OUTPUT", context, fields, QgsWkbTypes.Unknown, crs)
        if sink is None:
            raise QgsProcessingException(self.invalidSinkError(parameters, "OUTPUT"))
        core = bridge.core()
        parts = list(bridge.batches(features))
        rejected_count = 0
        for k, (start, end) in enumerate(parts):
            if feedback.isCanceled():
                break
            try:
                row, part, kind, length, width, elong, wkb, rejected = core.labels(
                    features.wkbs[start:end], json.dumps(options), None
                )
            except core.PipelineError as e:
                raise QgsProcessingException(str(e)) from None
            for j, r in enumerate(row):
                i = start + r
                g = bridge.geometry(wkb[j])
                z = bridge.minzoom(g, kind[j], length[j], width[j], crs, options["min_pixels"])
                attrs = [features.attributes[i][c] for c in carried]
                attrs += [features.fids[i], part[j], kind[j], length[j], width[j], elong[j], z, rejected[j]]
                f = QgsFeature()
                f.setAttributes(attrs)
                f.setGeometry(g)
                sink.addFeature(f, QgsFeatureSink.FastInsert)
                if rejected[j] is not None:
                    rejected_count += 1
                    feedback.reportError(f"feature {features.fids[i]} rejected: {rejected[j]}")
            feedback.setProgress(10 + 90 * (k + 1) / len(parts))
        return {"OUTPUT": dest, "FEATURES_READ": len(features), "FEATURES_REJECTED": rejected_count}


ALGORITHMS = [SkeletoniseAlgorithm, PipelineAlgorithm, LabelAlgorithm]
