"""The Processing algorithms of the `skeletonise` provider.

Each runs the command line's per-feature path in-process (the skeletonise
wheel); option names and defaults are the pipeline file's. Features read are
all written: a feature that cannot be processed gets a row with a NULL
geometry and its reason in ``rejected``, and the reason is reported through
the feedback.
"""

import json
import math
import os

import numpy as np

from qgis.core import (
    QgsFeature,
    QgsFeatureRequest,
    QgsFeatureSink,
    QgsProcessing,
    QgsProcessingAlgorithm,
    QgsProcessingParameterDefinition,
    QgsProcessingException,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFeatureSource,
    QgsProcessingParameterField,
    QgsProcessingParameterFile,
    QgsProcessingParameterNumber,
    QgsProcessingParameterString,
    QgsVectorLayer,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QCoreApplication
from qgis.PyQt.QtGui import QIcon

from . import bridge

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

    def _tooltips(self):
        """Each parameter's help (its tooltip in the dialog): its entry of the help text."""
        import re

        entries = {}
        for line in self.HELP.split("\n"):
            m = re.match(r"((?:<b>[^<]+</b>(?:, | and )?)+): (.*)", line)
            if m:
                for name in re.findall(r"<b>([^<]+)</b>", m.group(1)):
                    entries[name] = m.group(2)
        for p in self.parameterDefinitions():
            text = entries.get(p.description().split(" (")[0])
            if text and hasattr(p, "setHelp"):
                p.setHelp(_tr(text))

    def canExecute(self):  # noqa: N802
        if bridge.version() is None:
            return False, f"The skeletonise Python package is missing. {bridge.install_hint()}"
        return True, ""

    # --- shared steps -------------------------------------------------------

    def _refuse_outputs_onto_inputs(self, parameters, context):
        """No sink may be written into a file an input is read from (a GeoPackage output replaces
        the whole file): the command line's rule, never an overwritten input."""
        inputs = {}
        for p in self.parameterDefinitions():
            if p.isDestination() or p.name() not in parameters or parameters[p.name()] is None:
                continue
            if p.type() in ("source", "vector", "file"):
                layer = self.parameterAsVectorLayer(parameters, p.name(), context) if p.type() != "file" else None
                path = layer.source() if layer is not None else self.parameterAsString(parameters, p.name(), context)
                path = path.split("|")[0]
                if path and os.path.exists(path):
                    inputs[os.path.realpath(path)] = p.name()
        for p in self.destinationParameterDefinitions():
            if parameters.get(p.name()) is None:
                continue
            dest = self.parameterAsOutputLayer(parameters, p.name(), context) or ""
            dest = dest.split("|")[0]
            if dest.startswith("ogr:") or not dest or dest.startswith("memory:"):
                continue
            real = os.path.realpath(dest)
            if real in inputs:
                raise QgsProcessingException(
                    f"the output {p.name()} ({dest}) is the file the input {inputs[real]} is read from, and "
                    "writing it would replace that file: choose another output file"
                )

    def _input(self, parameters, context):
        self._refuse_outputs_onto_inputs(parameters, context)
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

    def _connect(self, parameters, context, crs):
        """The optional CONNECT line layer, in the polygons' CRS: (WKB lines, FIDs) or None."""
        if parameters.get("CONNECT") is None:
            return None
        lines = self.parameterAsSource(parameters, "CONNECT", context)
        if lines is None:
            return None
        request = QgsFeatureRequest().setDestinationCrs(crs, context.transformContext())
        wkbs, fids = [], []
        for f in lines.getFeatures(request):
            fids.append(int(f.id()))
            wkbs.append(bytes(f.geometry().asWkb()) if f.hasGeometry() else None)
        return wkbs, fids

    def _side_inputs(self, pipeline, path, context, crs):
        """The side input layers the pipeline file names for its registered steps (`streets.units`),
        opened by QGIS's OGR provider (a relative source from the working directory, as the
        command line opens it, else from the pipeline file's folder) with their `where`, in the
        polygons' CRS: ``{step: (WKB geometries, FIDs)}``."""
        out = {}
        for step, key, source, layer, where in pipeline.side_inputs:
            name = f"steps.{step}.{key}"
            candidates = [source]
            if path and not os.path.isabs(source):
                candidates.append(os.path.join(os.path.dirname(os.path.abspath(path)), source))
            found = next((c for c in candidates if os.path.exists(c)), source)
            uri = found if layer is None else f"{found}|layername={layer}" if isinstance(layer, str) else f"{found}|layerid={layer}"
            side = QgsVectorLayer(uri, name, "ogr")
            if not side.isValid():
                raise QgsProcessingException(f"`{name}`: cannot open layer {layer!r} of `{source}`; check its source and layer")
            if where and not side.setSubsetString(where):
                raise QgsProcessingException(f"`{name}.where`: invalid filter `{where}`")
            request = QgsFeatureRequest().setDestinationCrs(crs, context.transformContext())
            wkbs, fids = [], []
            for f in side.getFeatures(request):
                fids.append(int(f.id()))
                wkbs.append(bytes(f.geometry().asWkb()) if f.hasGeometry() else None)
            out[step] = (wkbs, fids)
        return out

    def _units(self, parameters, context, crs):
        """The NEIGHBOURS coverage, in the polygons' CRS: (WKB polygons, FIDs, attributes by FID, source)."""
        if parameters.get("NEIGHBOURS") is None:
            raise QgsProcessingException(
                "the pipeline has a `partition` step, which gives the polygons' area to the units of a coverage: "
                "give that coverage as Neighbours (NEIGHBOURS)"
            )
        units = self.parameterAsSource(parameters, "NEIGHBOURS", context)
        if units is None:
            raise QgsProcessingException(self.invalidSourceError(parameters, "NEIGHBOURS"))
        if units.featureCount() == 0:
            # The command line's refusal of an empty `input.neighbours`, before any work.
            name = bridge.layer_name(self.parameterAsVectorLayer(parameters, "NEIGHBOURS", context), units)
            raise QgsProcessingException(
                f"`input.neighbours`: layer `{name}` has no units; give the coverage whose units take the area "
                "(Neighbours)"
            )
        request = QgsFeatureRequest().setDestinationCrs(crs, context.transformContext())
        wkbs, fids, attributes = [], [], {}
        for f in units.getFeatures(request):
            fids.append(int(f.id()))
            attributes[int(f.id())] = f.attributes()
            wkbs.append(bytes(f.geometry().asWkb()) if f.hasGeometry() else None)
        return wkbs, fids, attributes, units

    # The layers an algorithm can write beside the skeletons, by sink: (layer, geometry type).
    LAYER_SINKS = {
        "AREAS": ("areas", QgsWkbTypes.Polygon),
        "COVERAGE": ("coverage", QgsWkbTypes.MultiPolygon),
        "BOUNDARIES": ("boundaries", QgsWkbTypes.MultiLineString),
    }

    def _pipeline_rows(self, pipeline, parameters, context, feedback, explode, snap=0.0):
        """Runs ``pipeline`` on INPUT, writing OUTPUT (the skeletons), CANDIDATES
        when given and the step's layers (AREAS with collapse; COVERAGE,
        BOUNDARIES and AREAS with partition) where the algorithm has the sink."""
        source, skip = self._input(parameters, context)
        crs = source.sourceCrs()
        connect = self._connect(parameters, context, crs)
        try:
            # What the command line refuses of the inputs (prune mode network without lines), before any work.
            pipeline.check_inputs(connect=connect is not None)
        except bridge.core().PipelineError as e:
            raise QgsProcessingException(str(e)) from None
        collapse, partition = pipeline.collapse, pipeline.partition
        extra = {}
        if connect is not None:
            extra = {"connect": connect[0], "connect_fids": connect[1], "snap": snap}
        sides = self._side_inputs(pipeline, getattr(self, "_path", None), context, crs)
        if sides:
            extra["sides"] = sides
        unit_fields, unit_attributes, unit_skip = None, {}, set()
        if partition:
            if "NEIGHBOURS" not in [p.name() for p in self.parameterDefinitions()]:
                raise QgsProcessingException(
                    "the pipeline has a `partition` step, which gives the polygons' area to the units of a "
                    "coverage: run it with Partition into neighbours (skeletonise:partition)"
                )
            wkbs, fids, unit_attributes, units = self._units(parameters, context, crs)
            unit_fields = units.fields()
            layer = self.parameterAsVectorLayer(parameters, "NEIGHBOURS", context)
            if layer is not None:
                unit_skip = {unit_fields.at(i).name() for i in layer.dataProvider().pkAttributeIndexes()}
            extra.update(neighbours=wkbs, neighbour_fids=fids)
            if "SNAP" in [p.name() for p in self.parameterDefinitions()]:
                neighbour_snap = self.parameterAsDouble(parameters, "SNAP", context)
                if neighbour_snap > 0:
                    extra["neighbour_snap"] = neighbour_snap
        features = bridge.read(source, pipeline.make_valid, feedback)
        carried = bridge.source_fields(source.fields(), skip)
        # The pipeline's own plan (a registered step's layers too), as the command line's writer.
        reserved = pipeline.reserved(connect=connect is not None, explode=explode)
        names = [p.name() for p in self.parameterDefinitions()]
        sinks = [("OUTPUT", "skeletons", QgsWkbTypes.MultiLineString)]
        if "CANDIDATES" in names and parameters.get("CANDIDATES") is not None:
            sinks.append(("CANDIDATES", "candidates", QgsWkbTypes.MultiLineString))
        for key, (layer, kind) in self.LAYER_SINKS.items():
            if key in names and (layer != "areas" or collapse or partition) and (layer == "areas" or partition):
                sinks.append((key, layer, kind))
        # A registered step's layer, when the pipeline has the step and the algorithm the sink.
        for key, layer, kind in _step_sinks():
            if key in names and parameters.get(key) is not None:
                sinks.append((key, layer, kind))
        results, outputs = {}, {}
        columns = {}
        for key, layer, kind in sinks:
            try:
                # The pipeline's own plan: the columns the command line writes.
                columns[key] = pipeline.layer_columns(layer, connect=connect is not None, explode=explode)
            except ValueError:
                continue
        sinks = [s for s in sinks if s[0] in columns]
        for key, layer, kind in sinks:
            tool, carries = columns[key]
            if layer == "coverage":
                fields_of, keep = unit_fields, bridge.source_fields(unit_fields, unit_skip)
            else:
                fields_of, keep = source.fields(), carried if carries else []
            fields = bridge.output_fields(
                fields_of, keep, tool, rejected=layer == "skeletons", reserved=reserved
            )
            sink, dest = self.parameterAsSink(parameters, key, context, fields, kind, crs)
            if sink is None and self.parameterDefinition(key).flags() & QgsProcessingParameterDefinition.FlagOptional == 0:
                raise QgsProcessingException(self.invalidSinkError(parameters, key))
            if sink is not None:
                outputs[key] = (sink, layer, keep)
                results[key] = dest
        counts = {"read": len(features), "written": 0, "rejected": 0}
        # A partition merges adjacent polygons and grows the coverage once all are done, and a
        # registered step's finish reads every feature's rows: one call.
        parts = [(0, len(features))] if partition or pipeline.finishes else list(bridge.batches(features))
        by_fid = {fid: i for i, fid in enumerate(features.fids)}
        for k, (start, end) in enumerate(parts):
            done = {}
            try:
                # The candidates come from the same pass as the skeletons.
                done["skeletons"] = bridge.run_pipeline(
                    pipeline,
                    features,
                    (start, end),
                    feedback,
                    candidates=False,
                    explode=explode,
                    with_candidates="CANDIDATES" in outputs,
                    **extra,
                )
            except bridge.Cancelled:
                feedback.pushInfo(f"cancelled: the first {start} of {len(features)} features are written")
                break
            except (bridge.core().RejectedError, bridge.core().PipelineError) as e:
                raise QgsProcessingException(str(e)) from None
            # Counted whether or not the skeletons are written (a partition's are optional).
            counts["rejected"] += done["skeletons"]["counts"]["rejected"]
            counts["written"] += done["skeletons"]["counts"]["written"]
            if "OUTPUT" not in outputs and done["skeletons"]["counts"]["rejected"]:
                feedback.reportError(
                    f"{done['skeletons']['counts']['rejected']} features rejected; write the Skeletons output to see why"
                )
            for _key, (sink, layer, keep) in outputs.items():
                if layer == "skeletons":
                    bridge.write(sink, done[layer], features, start, keep, feedback)
                    continue
                rows_of = done["skeletons"]["layers"][layer]
                if rows_of["fields"] == "neighbours":
                    attributes = lambda fid: unit_attributes.get(fid)  # noqa: E731
                else:
                    attributes = lambda fid: features.attributes[by_fid[fid]] if fid in by_fid else None  # noqa: E731
                bridge.write_layer(sink, rows_of, attributes, keep)
            feedback.setProgress(10 + 90 * (k + 1) / len(parts))
        feedback.pushInfo(
            f"{counts['read']} features read, {counts['written']} written, {counts['rejected']} rejected"
        )
        results["FEATURES_READ"] = counts["read"]
        results["FEATURES_REJECTED"] = counts["rejected"]
        return results


def core_columns(layer, explode, collapse=False):
    """The tool's columns of ``layer`` and whether it carries the input's fields."""
    return bridge.core().columns(layer, explode, collapse)


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
        _method_parameters(self)
        self.addParameter(QgsProcessingParameterBoolean("EXPLODE", _tr("One row per polygon part"), defaultValue=False))
        _sinks(self)
        self._tooltips()

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        doc = {"steps": _method_steps(self, parameters, context)}
        pipeline = bridge.options_pipeline(doc, "skeletonise:skeletonise")
        explode = self.parameterAsBoolean(parameters, "EXPLODE", context)
        return self._pipeline_rows(pipeline, parameters, context, feedback, explode)


def _modes(step, key, leave_out=()):
    """The values of a step's option that is one of a few texts (``("PruneParams", "mode")``, …)
    in the schema's order, less ``leave_out``, and the index of its default: the choices the
    command line has, none copied by hand. Empty without the wheel (the algorithm then says what
    to install)."""
    options = dict(_options(step))
    option = options.get(key)
    choices = [c for c in (_choices(option) or []) if c not in leave_out] if option else []
    default = choices.index(option["default"]) if choices and option["default"] in choices else 0
    return choices, default


def _methods():
    """The methods the skeleton step may list, from the schema: its default list first, in that
    order (the order saved models' indices keep, ties in selection going to the earlier method),
    then any other the wheel has. Empty without the wheel (the algorithm then says what to
    install)."""
    options = dict(_options("SkeletonParams"))
    if "methods" not in options:
        return []
    default = list(options["methods"].get("default") or [])
    try:
        every = json.loads(bridge.core().schema())["$defs"]["MethodId"]["enum"]
    except (QgsProcessingException, KeyError):
        every = default
    return default + [m for m in every if m not in default]


# Pruning to a network needs its lines (the collapse algorithm's connect lines only legs them).
PRUNE = ("PruneParams", "mode", ("network",))
EXTEND = ("ExtendParams", "mode", ())
SELECT = ("SelectParams", "by", ())


def _mode_parameter(alg, name, label, spec):
    """An enum parameter of a step's option (``PRUNE``, ``EXTEND``, ``SELECT``) from the schema;
    none without the wheel (the algorithm cannot run, and says what to install)."""
    choices, default = _modes(*spec)
    if not choices:
        return
    alg.addParameter(QgsProcessingParameterEnum(name, label, options=choices, defaultValue=default))


def _mode_value(alg, name, spec, parameters, context):
    """The value chosen for an enum parameter made by ``_mode_parameter`` (without the wheel, the
    message saying what to install)."""
    choices = _modes(*spec)[0]
    if not choices:
        bridge.core()
    return choices[alg.parameterAsEnum(parameters, name, context)]


def _method_parameters(alg, choose=True):
    """METHODS, PRUNE, MIN_LENGTH, EXTEND and SELECT: the skeleton, prune, extend and select steps
    (without METHODS and SELECT when the method is not a choice: collapse draws the medial axis)."""
    methods = _methods()
    if choose and methods:
        alg.addParameter(
            QgsProcessingParameterEnum(
                "METHODS", _tr("Methods"), options=methods, allowMultiple=True, defaultValue=list(range(len(methods)))
            )
        )
    _mode_parameter(alg, "PRUNE", _tr("Prune"), PRUNE)
    alg.addParameter(
        QgsProcessingParameterNumber(
            "MIN_LENGTH",
            _tr("Minimum leg length (layer units; 0: none)"),
            QgsProcessingParameterNumber.Double,
            defaultValue=0.0,
            minValue=0.0,
        )
    )
    _mode_parameter(alg, "EXTEND", _tr("Extend"), EXTEND)
    if choose:
        _mode_parameter(alg, "SELECT", _tr("Select by"), SELECT)


def _prune_extend(alg, parameters, context):
    """The prune and extend steps of PRUNE, MIN_LENGTH and EXTEND, as the pipeline file's."""
    prune = {"mode": _mode_value(alg, "PRUNE", PRUNE, parameters, context)}
    min_length = alg.parameterAsDouble(parameters, "MIN_LENGTH", context)
    if min_length > 0:
        prune["min_length"] = min_length
    return [{"prune": prune}, {"extend": {"mode": _mode_value(alg, "EXTEND", EXTEND, parameters, context)}}]


def _method_steps(alg, parameters, context, collapse=None):
    """The steps of the method parameters (a collapse step after extend when given, with the
    medial axis alone, as the collapse step needs), as the pipeline file's."""
    if collapse is not None:
        methods = ["MA"]
    else:
        every = _methods()
        if not every:
            bridge.core()  # without the wheel: raises, saying what to install
        methods = [every[i] for i in alg.parameterAsEnums(parameters, "METHODS", context)]
    if not methods:
        raise QgsProcessingException("`methods`: choose at least one method")
    steps = [{"prepare": {}}, {"skeleton": {"methods": methods}}] + _prune_extend(alg, parameters, context)
    if collapse is not None:
        steps += [{"collapse": collapse}, {"score": {}}, {"select": {}}]
    else:
        steps += [{"score": {}}, {"select": {"by": _mode_value(alg, "SELECT", SELECT, parameters, context)}}]
    return steps


def _partition_sinks(alg, required):
    """COVERAGE (required in Partition into neighbours), BOUNDARIES and AREAS: the partition's layers."""
    alg.addParameter(
        QgsProcessingParameterFeatureSink(
            "COVERAGE", _tr("Grown coverage"), QgsProcessing.TypeVectorPolygon, optional=not required, createByDefault=required
        )
    )
    alg.addParameter(
        QgsProcessingParameterFeatureSink(
            "BOUNDARIES", _tr("New boundaries"), QgsProcessing.TypeVectorLine, optional=True, createByDefault=required
        )
    )


def _connect_parameters(alg):
    alg.addParameter(
        QgsProcessingParameterFeatureSource(
            "CONNECT",
            _tr("Connecting lines (rivers, roads: the skeleton gets a leg to where they meet the polygon)"),
            [QgsProcessing.TypeVectorLine],
            optional=True,
        )
    )
    alg.addParameter(
        QgsProcessingParameterNumber(
            "SNAP",
            _tr("Snap distance (layer units)"),
            QgsProcessingParameterNumber.Double,
            defaultValue=0.0,
            minValue=0.0,
        )
    )


def _areas_sink(alg):
    alg.addParameter(
        QgsProcessingParameterFeatureSink(
            "AREAS", _tr("Kept areas"), QgsProcessing.TypeVectorPolygon, optional=True
        )
    )


class CollapseAlgorithm(_Algorithm):
    """Narrow polygons to lines, wide parts kept as areas (the collapse step)."""

    NAME = "collapse"
    DISPLAY = "Collapse narrow polygons"
    HELP = (
        "Collapses polygons to lines where they are narrower than a width and keeps them as areas where "
        "they are wider, cut across the polygon between, as the command line's collapse step: rivers "
        "that become lines where narrow and stay areas where wide, lakes on a river network.\n\n"
        "The collapse step's options (width, tolerance, min length, mode, min area) are its own, as "
        "`skeletonise schema` gives them (names, defaults, ranges; their help below and as the tooltip "
        "of each; 0 leaves min length unset: the width).\n\n"
        "<b>Polygons</b>: a polygon layer in a projected CRS.\n"
        "<b>Connecting lines</b>: optional line layer (rivers into a lake, roads): the skeleton gets a leg "
        "to every point where a line meets the polygon.\n"
        "<b>Snap distance</b>: a connecting line's end this close to the polygon's boundary meets it too "
        "(layer units; 0: only lines that touch or cross it).\n"
        "<b>Prune</b>, <b>Minimum leg length</b>, <b>Extend</b>: as in Skeletonise polygons; the lines are "
        "the medial axis's (MA), on whose inscribed discs the polygon is cut.\n"
        "<b>Skeletons</b>: the lines, with collapsed = 1 where the polygon collapsed.\n"
        "<b>Kept areas</b>: the pieces kept as areas, with cuts (where collapsed lines meet them)."
    )

    def shortHelpString(self):  # noqa: N802
        """The help text, with each option of the collapse step explained by its schema."""
        return _tr(self.HELP) + _tr(_options_help(_builtin_options(COLLAPSE_OPTIONS)))

    def initAlgorithm(self, config=None):  # noqa: N802
        _polygons(self)
        _option_parameters(self, _builtin_options(COLLAPSE_OPTIONS))
        _connect_parameters(self)
        _method_parameters(self, choose=False)
        _sinks(self, candidates=False)
        _areas_sink(self)
        self._tooltips()

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        collapse = _option_values(self, _builtin_options(COLLAPSE_OPTIONS), parameters, context)
        if not collapse.get("width", 0) > 0:
            raise QgsProcessingException("`width`: give the collapse width, a distance > 0 in the layer's units")
        doc = {"steps": _method_steps(self, parameters, context, collapse)}
        pipeline = bridge.options_pipeline(doc, "skeletonise:collapse")
        snap = self.parameterAsDouble(parameters, "SNAP", context)
        return self._pipeline_rows(pipeline, parameters, context, feedback, False, snap)


class PipelineAlgorithm(_Algorithm):
    """A pipeline file's steps on a layer (the Python package's ``apply``)."""

    NAME = "pipeline"
    DISPLAY = "Run a pipeline file"
    HELP = (
        "Runs the steps of a skeletonise pipeline file (YAML) on a polygon layer: the same file as "
        "`skeletonise run FILE.yaml` takes; its input and output sections are not used (the layers of "
        "this dialog are), except output.explode and on_error.\n\n"
        "<b>Polygons</b>: a polygon layer in a projected CRS.\n"
        "<b>Pipeline file</b>: the YAML file; it is validated as `skeletonise validate` does, with the "
        "same messages.\n"
        "<b>Connecting lines</b>, <b>Snap distance</b>: the line network of input.connect (for prune "
        "mode network, or legs to where the lines meet the polygons).\n"
        "<b>Overrides</b>: optional KEY=VALUE settings, as the command line's --set, separated by "
        "semicolons or new lines, e.g. steps.skeleton.methods=[MA]; steps.prune.mode=trunk.\n"
        "<b>Neighbours</b>: the coverage of a partition step (input.neighbours).\n"
        "<b>Skeletons</b>, <b>Candidates</b>: as in Skeletonise polygons.\n"
        "<b>Kept areas</b>: with a collapse step, as in Collapse narrow polygons; with a partition step, "
        "its remainders.\n"
        "<b>Grown coverage</b>, <b>New boundaries</b>: with a partition step, as in Partition into "
        "neighbours."
    )

    def shortHelpString(self):  # noqa: N802
        """The help text, with a line for each registered step's layer."""
        layers = "".join(
            f"\n<b>Layer `{layer}`</b>: the layer of a registered step, written when the pipeline has the step; "
            "a layer the step reads (e.g. streets.units) is opened from the pipeline file, as the command line opens it."
            for _key, layer, _kind in _step_sinks()
        )
        return _tr(self.HELP) + _tr(layers)

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
        _connect_parameters(self)
        self.addParameter(
            QgsProcessingParameterFeatureSource(
                "NEIGHBOURS", _tr("Neighbours (the coverage of a partition step)"), [QgsProcessing.TypeVectorPolygon], optional=True
            )
        )
        _sinks(self)
        _areas_sink(self)
        _partition_sinks(self, required=False)
        for key, layer, kind in _step_sinks():
            sink = QgsProcessingParameterFeatureSink(
                key, _tr(f"Layer `{layer}` (of a registered step)"),
                QgsProcessing.TypeVectorLine if kind in (QgsWkbTypes.LineString, QgsWkbTypes.MultiLineString)
                else QgsProcessing.TypeVectorPolygon if kind in (QgsWkbTypes.Polygon, QgsWkbTypes.MultiPolygon)
                else QgsProcessing.TypeVectorPoint if kind == QgsWkbTypes.Point
                else QgsProcessing.TypeVector,
                optional=True, createByDefault=False,
            )
            sink.setHelp(_tr(f"The `{layer}` layer, written when the pipeline has its step."))
            self.addParameter(sink)
        self._tooltips()

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        path = self.parameterAsFile(parameters, "PIPELINE", context)
        text = self.parameterAsString(parameters, "OVERRIDES", context) or ""
        overrides = [s.strip() for s in text.replace("\n", ";").split(";") if s.strip()]
        core = bridge.core()
        try:
            pipeline = core.Pipeline.load(path, overrides)
        except (core.PipelineError, OSError) as e:
            raise QgsProcessingException(str(e)) from None
        snap = self.parameterAsDouble(parameters, "SNAP", context)
        self._path = path
        return self._pipeline_rows(pipeline, parameters, context, feedback, pipeline.explode, snap)


_SINK_TYPES = {
    "linestring": QgsWkbTypes.LineString,
    "multilinestring": QgsWkbTypes.MultiLineString,
    "polygon": QgsWkbTypes.Polygon,
    "multipolygon": QgsWkbTypes.MultiPolygon,
    "point": QgsWkbTypes.Point,
    "none": QgsWkbTypes.NoGeometry,
}


def _step_sinks():
    """The registered steps' layers a pipeline algorithm can write (not those of mixed geometry,
    such as `labels`, which QGIS cannot hold in one layer: the Label lines algorithm writes them):
    ``(parameter, layer, QGIS geometry type)``; none without the wheel."""
    try:
        layers = bridge.core().step_layers()
    except QgsProcessingException:
        return []
    # The layers with sinks of their own (AREAS, COVERAGE, BOUNDARIES: the collapse and partition
    # algorithms' parameters) are not repeated.
    own = {layer for layer, _ in _Algorithm.LAYER_SINKS.values()}
    return [
        (f"STEP_{layer.upper()}", layer, _SINK_TYPES[kind])
        for _step, layer, kind, _ in layers
        if kind in _SINK_TYPES and layer not in own
    ]


def _options(definition, first=()):
    """The options of a step from the pipeline file's JSON Schema (the wheel's ``schema()``, which
    ``skeletonise schema`` prints), ``definition`` naming them in its ``$defs``: ``(key, schema)``
    pairs, each schema resolved, with ``nullable`` (the option may be left unset) and ``required``;
    the keys of ``first`` first, the others in the schema's order. Empty without the wheel (the
    algorithm then says what to install)."""
    try:
        schema = json.loads(bridge.core().schema())
    except QgsProcessingException:
        return []
    defs = schema["$defs"]
    props = defs.get(definition, {}).get("properties", {})
    required = defs.get(definition, {}).get("required", [])

    def resolve(v):
        ref = v.get("$ref", "")
        return defs[ref.rsplit("/", 1)[-1]] if ref.startswith("#/$defs/") else v

    def option(v):
        o = dict(resolve(v), default=v.get("default"), description=v.get("description", ""))
        types = o.get("type") if isinstance(o.get("type"), list) else [o.get("type")]
        o["type"] = next((t for t in types if t != "null"), None)
        return dict(o, nullable="null" in types)

    keys = [k for k in first if k in props] + [k for k in props if k not in first]
    return [(key, dict(option(props[key]), required=key in required)) for key in keys]


def _step_options(step):
    """The options of the registered step ``step`` (see ``_options``)."""
    return _options(f"{step}_options")


# The built-in steps whose options are parameters of their algorithm, in the order shown, and the
# parameter names that differ from the option's key in capitals (where another step's parameter of
# the algorithm has that name: prune's MIN_LENGTH).
COLLAPSE_OPTIONS = ("CollapseParams", ("width", "tolerance", "min_length", "mode", "min_area"))
PARTITION_OPTIONS = ("partition_options", ("overlap", "unowned", "width", "tolerance", "min_length"))
RENAMED = {"CollapseParams": {"min_length": "COLLAPSE_MIN_LENGTH"},
           "partition_options": {"min_length": "PARTITION_MIN_LENGTH"}}


def _builtin_options(spec):
    """``(parameter name, key, schema)`` of a built-in step's options (``COLLAPSE_OPTIONS``, …)."""
    definition, first = spec
    names = RENAMED.get(definition, {})
    return [(names.get(key, key.upper()), key, option) for key, option in _options(definition, first)]


def _choices(option):
    """The values of an option that is one of a few texts, or None."""
    if "enum" in option:
        return [str(v) for v in option["enum"]]
    if "oneOf" in option and all("const" in o for o in option["oneOf"]):
        return [str(o["const"]) for o in option["oneOf"]]
    return None


def _step_parameters(alg, step):
    """The parameters of a registered step's options, from its schema: names (the key in capitals),
    defaults, ranges (an exclusive bound as the nearest number inside it) and help."""
    _option_parameters(alg, [(key.upper(), key, option) for key, option in _step_options(step)])


def _option_parameters(alg, options):
    """The parameters of ``(name, key, schema)`` options: defaults, ranges (an exclusive bound as
    the nearest number inside it) and help from the schema; an option that may be left unset is 0
    when it is (its help says what unset means)."""
    for name, key, option in options:
        label = _tr(key.replace("_", " ").capitalize())
        choices = _choices(option)
        if choices is not None:
            default = choices.index(option["default"]) if option["default"] in choices else 0
            p = QgsProcessingParameterEnum(name, label, options=choices, defaultValue=default)
        elif option.get("type") in ("number", "integer"):
            bounds = {}
            for bound, plain, exclusive, towards in (("minValue", "minimum", "exclusiveMinimum", math.inf),
                                                     ("maxValue", "maximum", "exclusiveMaximum", -math.inf)):
                if plain in option:
                    bounds[bound] = float(option[plain])
                elif exclusive in option:
                    bounds[bound] = math.nextafter(float(option[exclusive]), towards)
            kind = QgsProcessingParameterNumber.Integer if option["type"] == "integer" else QgsProcessingParameterNumber.Double
            default = option["default"]
            if option["nullable"]:
                # Unset is 0, below every value it may take.
                bounds["minValue"] = 0.0
                label = _tr(f"{key.replace('_', ' ').capitalize()} (0: unset)")
                default = 0.0 if default is None else default
            p = QgsProcessingParameterNumber(name, label, kind, default, **bounds)
        elif option.get("type") == "boolean":
            p = QgsProcessingParameterBoolean(name, label, bool(option["default"]))
        else:
            continue
        p.setHelp(_tr(option["description"]))
        alg.addParameter(p)


def _step_values(alg, step, parameters, context):
    """The registered step's options as the user set them (the keys of its schema)."""
    return _option_values(alg, [(key.upper(), key, option) for key, option in _step_options(step)], parameters, context)


def _option_values(alg, options, parameters, context):
    """The options of ``(name, key, schema)`` as the user set them (an unset one, 0, left out)."""
    out = {}
    for name, key, option in options:
        choices = _choices(option)
        if choices is not None:
            out[key] = choices[alg.parameterAsEnum(parameters, name, context)]
        elif option.get("type") == "integer":
            out[key] = alg.parameterAsInt(parameters, name, context)
        elif option.get("type") == "number":
            out[key] = alg.parameterAsDouble(parameters, name, context)
        elif option.get("type") == "boolean":
            out[key] = alg.parameterAsBool(parameters, name, context)
        if option.get("nullable") and out.get(key) == 0:
            del out[key]
    return out


def _options_help(options):
    """Each option's help from its schema, one paragraph each, for an algorithm's help text."""
    return "".join(f"\n<b>{key.replace('_', ' ').capitalize()}</b>: {option['description']}" for _name, key, option in options)


class LabelAlgorithm(_Algorithm):
    """One label line (or point) per polygon part, for curved labels."""

    NAME = "label"
    DISPLAY = "Label lines"
    HELP = (
        "One label per polygon part, as the command line's label step: a smooth line along the medial "
        "axis where the part is elongated enough to carry a curved name, otherwise the centre of its "
        "largest inscribed disc (the pole of inaccessibility). Holes (islands) are respected. The "
        "options are the label step's (their help is the tooltip of each).\n\n"
        "<b>Polygons</b>: a polygon layer in a projected CRS.\n"
        "<b>Label lines</b>: the parts labelled along a line (kind = line), and the parts without a "
        "label (no geometry: kind = none for a part thinner than the axis's grid, or the reason in "
        "rejected); columns: the source's fields, src_fid, polygon_part, kind, length, max_width, "
        "elongation, minzoom (the smallest web-map zoom at which the label is shown, at its latitude), "
        "rejected.\n"
        "<b>Label points</b>: the parts labelled at a point (kind = point), the same columns. Together "
        "the two layers are the command line's labels layer: one row per polygon part."
    )

    def shortHelpString(self):  # noqa: N802
        """The help text, with each option of the label step explained by its schema."""
        options = _options_help([(key.upper(), key, option) for key, option in _step_options("label")])
        return _tr(self.HELP) + _tr(options)

    def initAlgorithm(self, config=None):  # noqa: N802
        _polygons(self)
        _step_parameters(self, "label")
        # Two layers of one geometry type each: QGIS cannot make a temporary layer of mixed
        # geometries, and lines and points are styled apart.
        self.addParameter(QgsProcessingParameterFeatureSink("OUTPUT", _tr("Label lines"), QgsProcessing.TypeVectorLine))
        self.addParameter(QgsProcessingParameterFeatureSink("POINTS", _tr("Label points"), QgsProcessing.TypeVectorPoint))
        self._tooltips()

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        source, skip = self._input(parameters, context)
        options = _step_values(self, "label", parameters, context)
        # The command line's pipeline: repaired geometries keep their polygons (a spike's line left
        # out), the medial axis made once by the skeleton step, the label step's rows.
        doc = {"steps": [{"prepare": {"make_valid": True, "min_area": 0.0}}, {"skeleton": {"methods": ["MA"]}},
                         {"label": options}]}
        pipeline = bridge.options_pipeline(doc, "label")
        features = bridge.read(source, True, feedback)
        carried = bridge.source_fields(source.fields(), skip)
        tool, _ = pipeline.layer_columns("labels")
        fields = bridge.output_fields(source.fields(), carried, tool, reserved=pipeline.reserved())
        crs = source.sourceCrs()
        sinks, results = {}, {}
        for key, kind in (("OUTPUT", QgsWkbTypes.LineString), ("POINTS", QgsWkbTypes.Point)):
            sink, dest = self.parameterAsSink(parameters, key, context, fields, kind, crs)
            if sink is None:
                raise QgsProcessingException(self.invalidSinkError(parameters, key))
            sinks[key], results[key] = sink, dest
        parts = list(bridge.batches(features))
        by_fid = {fid: i for i, fid in enumerate(features.fids)}
        proj = crs.toProj() if crs.isValid() else None
        rejected_count = 0
        for k, (start, end) in enumerate(parts):
            try:
                done = bridge.run_pipeline(pipeline, features, (start, end), feedback, candidates=False,
                                           explode=False, proj=proj or None)
            except bridge.Cancelled:
                feedback.pushInfo(f"cancelled: the first {start} of {len(features)} features are written")
                break
            except (bridge.core().RejectedError, bridge.core().PipelineError) as e:
                raise QgsProcessingException(str(e)) from None
            layer = done["layers"]["labels"]
            cols = bridge.columns(layer)
            wkbs = layer["geometry"][1]
            # Each label row at its feature's place, a rejected feature's row (its reason) among them.
            out = []
            for j, values in enumerate(zip(*cols)):
                out.append((by_fid[values[0]], j, list(values) + [None], wkbs[j]))
            reasons = bridge.columns(done)[-1]
            for j, r in enumerate(done["row"].tolist()):
                if reasons[j] is not None:
                    i = start + r
                    out.append((i, -1, [features.fids[i]] + [None] * (len(tool) - 1) + [reasons[j]], None))
                    rejected_count += 1
                    feedback.reportError(f"feature {features.fids[i]} rejected: {reasons[j]}")
            for i, _, values, wkb in sorted(out, key=lambda o: (o[0], o[1])):
                f = QgsFeature()
                f.setAttributes([features.attributes[i][c] for c in carried] + values)
                g = bridge.geometry(wkb)
                if not g.isNull():
                    f.setGeometry(g)
                kind = values[tool.index(("kind", "text"))]
                if not sinks["POINTS" if kind == "point" else "OUTPUT"].addFeature(f, QgsFeatureSink.FastInsert):
                    raise QgsProcessingException(f"could not write a feature of FID {features.fids[i]} to the output")
            feedback.setProgress(10 + 90 * (k + 1) / len(parts))
        return dict(results, FEATURES_READ=len(features), FEATURES_REJECTED=rejected_count)


class PartitionAlgorithm(_Algorithm):
    """A collapsed polygon's area given to the units around it, along the centreline."""

    NAME = "partition"
    DISPLAY = "Partition into neighbours"
    HELP = (
        "Gives the area of polygons to be collapsed (rivers, roads, narrow land cover) to the units of a "
        "coverage around them (municipalities, parcels, land-cover patches), the new boundary between two "
        "units running down the middle, as the command line's partition step: every point of the polygon "
        "goes to the unit whose bank is nearest, so the new boundary between two units is the medial axis "
        "between their banks. Adjacent polygons (reaches of one river) are merged first, vertex for "
        "vertex. The grown coverage stays a coverage: shared edges with identical vertices, no gap, no "
        "overlap, area conserved. The partition step's options (overlap, unowned, width, tolerance, min "
        "length) are its own, as `skeletonise schema` gives them (names, defaults, ranges; their help "
        "below and as the tooltip of each; 0 leaves width and min length unset: the whole polygon is "
        "given away). Overlap cut gives a cartographic boundary down the middle of the water, not the "
        "legal one.\n\n"
        "<b>Polygons</b>: the polygons to give away, in a projected CRS.\n"
        "<b>Neighbours</b>: the coverage of units around them (reprojected to the polygons' CRS when it "
        "differs). Real administrative units may contain their share of the water (the legal boundary "
        "inside it) or come from another source: see Overlap and Snap.\n"
        "<b>Snap</b>: unit vertices and edges within this distance of a polygon's bank are moved onto it "
        "(layer units; 0: 1e-7 × each polygon's extent, above a reprojection's round-off).\n"
        "<b>Prune</b>, <b>Minimum leg length</b>, <b>Extend</b>: the medial axis written to Skeletons, as in "
        "Skeletonise polygons.\n"
        "<b>Grown coverage</b>: every unit with its fields, src_fid (its FID), received (the area it "
        "received) and held (the area of the polygons it held before, cut out of it).\n"
        "<b>New boundaries</b>: the lines between two units that run through the polygons (left_fid, "
        "right_fid, length).\n"
        "<b>Remainders</b>: optional; the parts given to no unit (kind wide or unowned).\n"
        "<b>Skeletons</b>: optional; the polygons' medial axes."
    )

    def shortHelpString(self):  # noqa: N802
        """The help text, with each option of the partition step explained by its schema."""
        return _tr(self.HELP) + _tr(_options_help(_builtin_options(PARTITION_OPTIONS)))

    def initAlgorithm(self, config=None):  # noqa: N802
        _polygons(self)
        self.addParameter(
            QgsProcessingParameterFeatureSource("NEIGHBOURS", _tr("Neighbours (a coverage of units)"), [QgsProcessing.TypeVectorPolygon])
        )
        _option_parameters(self, _builtin_options(PARTITION_OPTIONS))
        number = QgsProcessingParameterNumber.Double
        self.addParameter(QgsProcessingParameterNumber("SNAP", _tr("Snap (layer units; 0: 1e-7 × extent)"), number, 0.0, minValue=0.0))
        _method_parameters(self, choose=False)
        _partition_sinks(self, required=True)
        self.addParameter(
            QgsProcessingParameterFeatureSink("AREAS", _tr("Remainders"), QgsProcessing.TypeVectorPolygon, optional=True, createByDefault=False)
        )
        self.addParameter(
            QgsProcessingParameterFeatureSink("OUTPUT", _tr("Skeletons"), QgsProcessing.TypeVectorLine, optional=True, createByDefault=False)
        )
        self._tooltips()

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        partition = _option_values(self, _builtin_options(PARTITION_OPTIONS), parameters, context)
        steps = [{"skeleton": {"methods": ["MA"]}}] + _prune_extend(self, parameters, context)
        doc = {"steps": steps + [{"partition": partition}]}
        pipeline = bridge.options_pipeline(doc, "skeletonise:partition")
        return self._pipeline_rows(pipeline, parameters, context, feedback, False)


def _key_text(value):
    """A join key as the command line reads it: integers without a decimal point, NULL as None."""
    if value is None or (hasattr(value, "isNull") and value.isNull()):
        return None
    if isinstance(value, float):
        return str(int(value)) if value.is_integer() else repr(value)
    return str(value)


class ScoreAlgorithm(_Algorithm):
    """Any line layer scored against a polygon layer (the `score` command)."""

    NAME = "score"
    DISPLAY = "Score skeletons"
    HELP = (
        "Scores skeleton lines made by any tool (GRASS v.voronoi -s, PostGIS ST_ApproximateMedialAxis, "
        "a hand-drawn centreline, …) against their polygons with the deviation and distortion metrics of "
        "Szombara's comparison of skeletonisation methods, as `skeletonise score` does: every polygon "
        "gets one row with its lines merged and their scores.\n\n"
        "<b>Polygons</b>: a polygon layer in a projected CRS.\n"
        "<b>Skeletons</b>: the line layer to score (reprojected to the polygons' CRS when it differs).\n"
        "<b>Skeleton key</b>: the skeleton field holding its polygon's key (the polygon's FID, or the "
        "Polygon key field); without it, each line goes to the polygon holding the midpoint of its first "
        "segment.\n"
        "<b>Polygon key</b>: the polygon field the skeleton key matches (default: the FID).\n"
        "<b>Label</b>: the method column's value (the other tool's name).\n"
        "<b>Scores</b>: the polygon's fields, src_fid, method, the scores and counts, and rejected (why a "
        "polygon has no score: no line joined, or most of its line outside it)."
    )

    def initAlgorithm(self, config=None):  # noqa: N802
        _polygons(self)
        self.addParameter(
            QgsProcessingParameterFeatureSource("SKELETONS", _tr("Skeletons (lines)"), [QgsProcessing.TypeVectorLine])
        )
        self.addParameter(
            QgsProcessingParameterField("SKELETON_KEY", _tr("Skeleton key"), parentLayerParameterName="SKELETONS", optional=True)
        )
        self.addParameter(
            QgsProcessingParameterField("POLYGON_KEY", _tr("Polygon key (default: the FID)"), parentLayerParameterName="INPUT", optional=True)
        )
        self.addParameter(QgsProcessingParameterString("LABEL", _tr("Label (the method column)"), defaultValue="external"))
        self.addParameter(QgsProcessingParameterFeatureSink("OUTPUT", _tr("Scores"), QgsProcessing.TypeVectorLine))
        self._tooltips()

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        source, skip = self._input(parameters, context)
        crs = source.sourceCrs()
        lines = self.parameterAsSource(parameters, "SKELETONS", context)
        if lines is None:
            raise QgsProcessingException(self.invalidSourceError(parameters, "SKELETONS"))
        skeleton_key = self.parameterAsString(parameters, "SKELETON_KEY", context) or None
        polygon_key = self.parameterAsString(parameters, "POLYGON_KEY", context) or None
        if polygon_key and not skeleton_key:
            raise QgsProcessingException(
                "a polygon key field needs a skeleton key field (the skeleton field that holds it); "
                "leave both empty to join by location"
            )
        # A key field the layer lacks is refused before any work, as `skeletonise score` refuses it.
        if skeleton_key:
            self._key_field(parameters, context, "SKELETONS", lines, skeleton_key, "skeleton")
        if polygon_key:
            self._key_field(parameters, context, "INPUT", source, polygon_key, "polygon")
        features = bridge.read(source, False, feedback)
        request = QgsFeatureRequest().setDestinationCrs(crs, context.transformContext())
        line_wkbs, line_keys = [], []
        for f in lines.getFeatures(request):
            line_wkbs.append(bytes(f.geometry().asWkb()) if f.hasGeometry() else None)
            if skeleton_key:
                line_keys.append(_key_text(f[skeleton_key]))
        keys = {}
        if skeleton_key:
            if polygon_key:
                index = source.fields().lookupField(polygon_key)
                polygon_keys = [_key_text(a[index]) for a in features.attributes]
            else:
                polygon_keys = [str(fid) for fid in features.fids]
            keys = {"polygon_keys": polygon_keys, "line_keys": line_keys}
        core = bridge.core()
        try:
            done = bridge.cancellable(
                feedback,
                core.score,
                features.wkbs,
                line_wkbs,
                fids=np.asarray(features.fids, dtype=np.int64),
                label=self.parameterAsString(parameters, "LABEL", context) or "external",
                output="wkb",
                **keys,
            )
        except bridge.Cancelled:
            return {}
        except ValueError as e:
            raise QgsProcessingException(str(e)) from None
        for why in done["unjoined"]:
            feedback.pushInfo(f"skeleton rows joined to no polygon and left out: {why}")
        carried = bridge.source_fields(source.fields(), skip)
        tool, carries = core_columns("skeletons", False)
        fields = bridge.output_fields(source.fields(), carried if carries else [], tool, reserved=core.reserved())
        sink, dest = self.parameterAsSink(parameters, "OUTPUT", context, fields, QgsWkbTypes.MultiLineString, crs)
        if sink is None:
            raise QgsProcessingException(self.invalidSinkError(parameters, "OUTPUT"))
        rejected = bridge.write(sink, done, features, 0, carried if carries else [], feedback)
        return {"OUTPUT": dest, "FEATURES_READ": len(features), "FEATURES_REJECTED": rejected}

    def _key_field(self, parameters, context, name, source, key, what):
        """Refuses a key field that the layer of parameter ``name`` does not have, naming the layer and
        its fields (without a GeoPackage's FID column), as `skeletonise score` does."""
        fields = source.fields()
        if fields.lookupField(key) >= 0:
            return
        layer = self.parameterAsVectorLayer(parameters, name, context)
        skip = set()
        if layer is not None:
            skip = {fields.at(i).name() for i in layer.dataProvider().pkAttributeIndexes()}
        names = [n for n in fields.names() if n not in skip]
        raise QgsProcessingException(
            f"{what} layer `{bridge.layer_name(layer, source)}`: has no field `{key}`; "
            f"fields: {', '.join(names) or '(none)'}"
        )


ALGORITHMS = [
    SkeletoniseAlgorithm,
    CollapseAlgorithm,
    PartitionAlgorithm,
    ScoreAlgorithm,
    PipelineAlgorithm,
    LabelAlgorithm,
]
