"""Collapse polygons to skeletons on GeoPandas and Dask-GeoPandas.

The same per-feature path as the ``skeletonise`` command line (Rust, the GIL
released, one thread per core; geometries go to Rust as WKB and come back as
GeoArrow buffers): methods VD, DVD, CDT, StSk and MA, pruning,
extension to the boundary, the deviation and distortion metrics of Szombara's
*Comparison of methods used in cartography for the skeletonisation of areal
objects*, and the choice of the best method per feature.

- :func:`skeletonise` — a GeoSeries (or shapely array) in, a GeoDataFrame with
  the columns of the ``skeletons`` layer out; options are the pipeline file's.
- :func:`apply` — the steps of a pipeline file on a GeoDataFrame, keeping its
  columns and index: the function to ``map_partitions`` on a Dask cluster.
- :func:`apply_layers` — the same with every layer of the output (the kept
  areas of ``collapse``; the grown coverage and new boundaries of
  ``partition``), as a dict of GeoDataFrames.

Every input row gives an output row: a feature that cannot be processed has a
NULL skeleton and its reason in ``rejected``; one skipped by ``min_area`` has a
NULL skeleton and no reason. Invalid polygons are repaired with shapely's
``make_valid`` (GEOS MakeValid, as GDAL's in the command line) when the
``prepare`` step's ``make_valid`` is on (the default), and get ``repaired = 1``.
"""

from __future__ import annotations

import functools
import json
import os
import time
from typing import Any, Mapping, Sequence, Union

import numpy as np

try:
    import pandas as pd
    import shapely
except ImportError as _missing:  # pragma: no cover - QGIS's Python, which the plugin drives through _core
    pd = shapely = None  # type: ignore[assignment]
    _GEO_MISSING: str | None = (
        f"{_missing.name} is not installed: skeletonise(), apply() and labels() need numpy, "
        "shapely and geopandas (pip install skeletonise installs them)"
    )
else:
    _GEO_MISSING = None

from . import _core
from ._core import PipelineError, RejectedError

__all__ = [
    "skeletonise",
    "apply",
    "describe",
    "schema",
    "columns",
    "PipelineError",
    "RejectedError",
    "__version__",
]

__version__: str = _core.__version__

StepOption = Union[bool, str, Mapping[str, Any], None]

# The key a bare string stands for, per step: `prune="trunk"` is `prune={"mode": "trunk"}`.
_SHORTHAND = {"prune": "mode", "extend": "mode", "select": "by"}


def describe() -> str:
    """The methods and every step's options with their defaults (``skeletonise methods``)."""
    return _core.describe()


def schema() -> dict:
    """The JSON Schema of the pipeline file (``skeletonise schema``)."""
    return json.loads(_core.schema())


def columns(layer: str = "skeletons", *, explode: bool = False) -> list[tuple[str, str]]:
    """The tool's columns of ``layer`` (``skeletons`` or ``candidates``) as ``(name, type)``.

    They come from the same table the command line's GeoPackage writer uses;
    the frames returned here add ``rejected`` (the reason, text) and the geometry.
    """
    return list(_core.columns(layer, explode)[0])


def _step(name: str, value: StepOption) -> dict | None:
    if value is None or value is False:
        return None
    if value is True:
        return {}
    if isinstance(value, str) and name in _SHORTHAND:
        return {_SHORTHAND[name]: value}
    if isinstance(value, Mapping):
        return dict(value)
    raise PipelineError(
        f"skeletonise(): `{name}`: expected a mapping of the step's options, "
        f"True (the step with its defaults) or False (no {name} step), not {value!r}"
    )


def _json_default(o: Any) -> Any:
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, (tuple, set, frozenset, np.ndarray)):
        return list(o)
    raise TypeError(f"{type(o).__name__} is not an option value")


def _options_pipeline(
    *,
    make_valid: bool | None,
    min_area: float | None,
    skeleton: Mapping[str, Any],
    steps: Mapping[str, StepOption],
    on_error: str,
) -> "_core.Pipeline":
    prepare = {k: v for k, v in (("make_valid", make_valid), ("min_area", min_area)) if v is not None}
    doc: dict[str, Any] = {"steps": [{"prepare": prepare}, {"skeleton": {k: v for k, v in skeleton.items() if v is not None}}]}
    for name, value in steps.items():
        body = _step(name, value)
        if body is not None:
            doc["steps"].append({name: body})
    doc["on_error"] = on_error
    try:
        text = json.dumps(doc, default=_json_default)
    except TypeError as e:
        raise PipelineError(f"skeletonise(): {e}") from None
    # Validating the options costs as much as skeletonising a small polygon:
    # the same options give the same (immutable) pipeline.
    pipeline = _OPTIONS.get(text)
    if pipeline is None:
        pipeline = _core.Pipeline.from_options(text, "skeletonise()")
        if len(_OPTIONS) >= 64:
            _OPTIONS.clear()
        _OPTIONS[text] = pipeline
    return pipeline


_OPTIONS: dict[str, "_core.Pipeline"] = {}


def _need_geo() -> None:
    """The GeoPandas functions need pandas and shapely; ``_core`` (which the
    QGIS plugin drives) needs only numpy."""
    if _GEO_MISSING is not None:
        raise ImportError(_GEO_MISSING)


def _geometry_array(geometries: Any) -> tuple[np.ndarray, pd.Index | None, Any]:
    _need_geo()
    """The geometries as a shapely array, with the index and CRS when they have them."""
    import geopandas as gpd

    if isinstance(geometries, gpd.GeoDataFrame):
        geometries = geometries.geometry
    if isinstance(geometries, gpd.GeoSeries):
        return np.asarray(geometries.values, dtype=object), geometries.index, geometries.crs
    if isinstance(geometries, pd.Series):
        return np.asarray(geometries.values, dtype=object), geometries.index, None
    arr = np.asarray(geometries, dtype=object)
    if arr.ndim != 1:
        raise ValueError("geometries must be one-dimensional: a GeoSeries, a shapely array or a list")
    return arr, None, None


def _prepare(arr: np.ndarray, make_valid: bool) -> tuple[np.ndarray, np.ndarray, float]:
    """Repairs invalid polygons as the command line's reader does (GEOS MakeValid)."""
    t0 = time.perf_counter()
    repaired = np.zeros(len(arr), dtype=bool)
    if make_valid and len(arr):
        present = ~shapely.is_missing(arr)
        bad = present & ~shapely.is_valid(arr)
        if bad.any():
            # A NaN or infinite coordinate cannot be repaired (GEOS raises for
            # the whole array): such a feature goes to Rust as it is and is
            # rejected alone, with the reason.
            rows = np.flatnonzero(bad)
            coords, at = shapely.get_coordinates(arr[rows], return_index=True)
            bad[rows[np.unique(at[~np.isfinite(coords).all(axis=1)])]] = False
        if bad.any():
            arr = arr.copy()
            arr[bad] = shapely.make_valid(arr[bad])
            repaired = bad
    return arr, repaired, time.perf_counter() - t0


# shapely's type ids of Polygon and MultiPolygon (shapely.GeometryType).
_POLYGONAL = (3, 6)


def _encode(arr: np.ndarray, exchange: str) -> Any:
    """The geometries for Rust: WKB (any geometry; points, lines and collections are
    then rejected with the command line's reason), or GeoArrow ragged arrays of
    polygons and multipolygons. WKB is the default: on 100 000 polygons (1.1 M
    vertices) ``shapely.to_wkb`` and the parse in Rust take half the time of
    ``shapely.to_ragged_array`` (scripts/bench-python.sh)."""
    if exchange == "wkb":
        return shapely.to_wkb(arr, output_dimension=2, byte_order=1, include_srid=False).tolist()
    if exchange != "geoarrow":
        raise ValueError(f"exchange must be `wkb` or `geoarrow`, not `{exchange}`")
    types = shapely.get_type_id(arr)
    missing = types < 0
    if not np.isin(types[~missing], _POLYGONAL).all():
        raise ValueError("exchange=`geoarrow` takes polygons and multipolygons only; use `wkb`")
    if not len(arr):
        return shapely.to_wkb(arr).tolist()
    if missing.any():
        arr = arr.copy()
        arr[missing] = shapely.Polygon()
    kind, coords, offsets = shapely.to_ragged_array(arr, include_z=False)
    return (
        int(kind),
        np.ascontiguousarray(coords, dtype=np.float64),
        [np.ascontiguousarray(o, dtype=np.int64) for o in offsets],
        missing if missing.any() else None,
    )


def _decode(geometry: tuple) -> np.ndarray:
    if geometry[0] == "wkb":
        return shapely.from_wkb(np.asarray(geometry[1], dtype=object))
    _, coords, line_offsets, geom_offsets, null = geometry
    if len(geom_offsets) <= 1:
        return np.empty(0, dtype=object)
    out = shapely.from_ragged_array(
        shapely.GeometryType.MULTILINESTRING,
        coords.reshape(-1, 2),
        (line_offsets, geom_offsets),
    )
    out[null] = None
    return out


def _column(kind: str, values: Any, reals: np.ndarray) -> Any:
    """A column of the result: nullable integers (``Int32``, ``Int64``), floats and
    ``string``, so that an empty frame (a Dask meta) has types that Arrow and
    GeoParquet know. Integers come as values of the column's width and a NULL
    mask, floats as a row of the block ``reals``, texts as Arrow buffers."""
    if kind in ("int32", "int64"):
        v, null = values
        # Already of the column's width: the masked array is the column.
        return _integers(v, null)
    if kind == "real":
        return reals[values]
    return _strings(*values)


def _integers(values: np.ndarray, null: np.ndarray) -> Any:
    """A nullable integer column of ``values`` (int32 or int64) and its NULL mask
    (bool), both of the right type already: the array is made without the
    constructor's checks where pandas has ``_simple_new``."""
    try:
        return pd.arrays.IntegerArray._simple_new(values, null)
    except AttributeError:
        return pd.arrays.IntegerArray(values, null)


# How ``string`` columns are made: None until probed, then the dtype of
# pandas' Arrow-backed strings, or False where ``string`` is not Arrow's.
_ARROW_STRINGS: Any = None


def _arrow_strings() -> Any:
    global _ARROW_STRINGS
    if _ARROW_STRINGS is None:
        _ARROW_STRINGS = False
        try:
            import pyarrow as pa

            probe = ["a", None]
            public = pd.array(probe, dtype="string")
            fast = _wrap_strings(pa.array(probe, type=pa.large_string()), public.dtype)
            if type(fast) is type(public) and vars(fast).keys() == vars(public).keys() and fast.equals(public):
                _ARROW_STRINGS = public.dtype
        except (ImportError, AttributeError, TypeError, ValueError):
            pass
    return _ARROW_STRINGS


def _wrap_strings(array: Any, dtype: Any) -> Any:
    """The ``ArrowStringArray`` of a large-string Arrow array, made as pandas
    makes the result of an operation (the constructor's type checks and cast
    cost five times as much as the array)."""
    import pyarrow as pa

    cls = pd.arrays.ArrowStringArray
    out = cls.__new__(cls)
    out._pa_array = pa.chunked_array([array])
    out._dtype = dtype
    out._cache = {}
    return out


def _strings(offsets: np.ndarray, data: bytes, null: Any) -> Any:
    """A ``string`` column from Arrow large-string buffers as Rust gives them:
    the start of every text in ``data`` (UTF-8) and the end, and which are NULL
    (``None`` when none is, ``True`` when all are, else a mask). Where pandas'
    ``string`` is Arrow's (pandas ≥ 3 with pyarrow) the buffers are the
    column's, without a Python string per row; else the texts are decoded for
    ``pd.array(..., dtype="string")``."""
    n = len(offsets) - 1
    dtype = _arrow_strings()
    if dtype is not False:
        import pyarrow as pa

        if null is True:
            # A column of NULLs (`rejected` and `note` in most calls).
            array = pa.nulls(n, pa.large_string())
        else:
            valid = None if null is None else pa.py_buffer(np.packbits(~null, bitorder="little"))
            array = pa.LargeStringArray.from_buffers(n, pa.py_buffer(offsets), pa.py_buffer(data), valid)
        return _wrap_strings(array, dtype)
    values = [
        None if null is True or (null is not None and null[i]) else data[offsets[i] : offsets[i + 1]].decode()
        for i in range(n)
    ]
    return pd.array(values, dtype="string")


def _geo_frame(tool: dict[str, Any], index: pd.Index, reals: np.ndarray | None = None) -> Any:
    """The GeoDataFrame of ``tool``'s columns (the last one, ``geometry``, the
    active geometry with its CRS). ``GeoDataFrame(tool, geometry=...)`` checks and
    copies every column: 0.4 ms of a call on one small polygon, more than its
    skeleton. The columns here are already of their final types, so the frame is
    assembled as pandas and geopandas assemble the result of an operation on a
    frame (``DataFrame._from_arrays``, ``GeoDataFrame._from_mgr``); where a
    pandas or geopandas version lacks those, the public constructor
    (``test_the_result_frame_is_the_one_geopandas_builds`` in tests/test_api.py
    checks that both give the same frame)."""
    import geopandas as gpd

    columns = _column_index(tuple(tool))
    try:
        mgr = _blocks(list(tool.values()), columns, index, reals)
    except (ImportError, AttributeError, TypeError, ValueError):
        mgr = None
    try:
        if mgr is None:
            frame = pd.DataFrame._from_arrays(
                list(tool.values()), columns=columns, index=index, verify_integrity=False
            )
            mgr = frame._mgr
        out = gpd.GeoDataFrame._from_mgr(mgr, axes=mgr.axes)
    except (AttributeError, TypeError):
        return _public_geo_frame(tool, index)
    out._geometry_column_name = "geometry"
    return out


def _blocks(arrays: list, columns: pd.Index, index: pd.Index, reals: np.ndarray | None = None) -> Any:
    """The block manager ``DataFrame._from_arrays`` would make of ``arrays``
    (float64 columns in one two-dimensional block, every extension array in
    its own), made directly: a fifth of the time, as the types are known.
    Anything else (an object column) is left to pandas (``TypeError``)."""
    global _BLOCK_API
    if _BLOCK_API is None:
        from pandas._libs.internals import BlockPlacement
        from pandas.core.internals.blocks import get_block_type, new_block
        from pandas.core.internals.managers import BlockManager

        _BLOCK_API = (BlockPlacement, get_block_type, new_block, BlockManager, pd.api.extensions.ExtensionArray)
    placement, get_block_type, new_block, manager, extension = _BLOCK_API
    floats = []
    blocks = []
    for i, a in enumerate(arrays):
        if type(a) is np.ndarray:
            if a.dtype != np.float64:
                raise TypeError("a NumPy column that is not float64")
            floats.append(i)
        elif isinstance(a, extension):
            # new_block's own steps, with the block class and the (immutable)
            # placement of each column kept from the calls before.
            klass = _BLOCK_TYPES.get(type(a))
            if klass is None:
                klass = _BLOCK_TYPES.setdefault(type(a), get_block_type(a.dtype))
            where = _PLACEMENTS.get(i)
            if where is None:
                where = _PLACEMENTS.setdefault(i, placement(slice(i, i + 1)))
            blocks.append(klass(a, ndim=2, placement=where, refs=None))
        else:
            raise TypeError("a column that is not an array")
    if floats:
        if reals is not None and reals.shape[0] == len(floats) and all(arrays[i].base is reals for i in floats):
            # The rows of the block Rust made, in column order: it is the frame's.
            values = reals
        else:
            values = np.array([arrays[i] for i in floats], dtype=np.float64)
        blocks.insert(0, new_block(values, placement(np.array(floats, dtype=np.intp)), ndim=2))
    return manager(tuple(blocks), [columns, index], verify_integrity=False)


_BLOCK_API: tuple | None = None
_BLOCK_TYPES: dict[type, Any] = {}
_PLACEMENTS: dict[int, Any] = {}


_COLUMN_INDEXES: dict[tuple, pd.Index] = {}


def _column_index(names: tuple) -> pd.Index:
    """The (immutable) column index of a layer's names, made once: a string
    index costs as much to build as the rest of a one-row frame."""
    index = _COLUMN_INDEXES.get(names)
    if index is None:
        index = _COLUMN_INDEXES.setdefault(names, pd.Index(list(names)))
    return index


def _public_geo_frame(tool: dict[str, Any], index: pd.Index) -> Any:
    import geopandas as gpd

    return gpd.GeoDataFrame(tool, index=index, geometry="geometry")


def _fids(index: pd.Index | None, n: int) -> np.ndarray:
    """``src_fid``: the index when it is an integer index (as pyogrio's ``fid_as_index``
    gives the source FIDs), else the 0-based position."""
    if index is not None and index.dtype.kind in "iu":
        return np.asarray(index, dtype=np.int64)
    return np.arange(n, dtype=np.int64)


@functools.lru_cache(maxsize=16)
def _proj_of(crs: Any) -> str | None:
    """``crs`` as a PROJ string, for the steps that need longitude and latitude (the ``label``
    step's ``minzoom``: the core transforms with it, on its worker threads); None without a CRS
    or where PROJ cannot write one."""
    if crs is None:
        return None
    import warnings

    import pyproj

    try:
        with warnings.catch_warnings():
            # "You will likely lose important projection information": only the latitude is used.
            warnings.simplefilter("ignore")
            return pyproj.CRS.from_user_input(crs).to_proj4()
    except pyproj.exceptions.CRSError:
        return None


def _check_call(crs: Any, threads: Any) -> None:
    """What the command line refuses before any work: a geographic CRS (radii
    and scores would be in degrees) and a number of threads out of range."""
    if crs is not None and getattr(crs, "is_geographic", False):
        raise ValueError(
            f"the geometries have the geographic CRS {crs.to_string()}; skeleton radii and "
            "scores need a projected CRS: reproject first, e.g. gdf.to_crs(gdf.estimate_utm_crs())"
        )
    if threads is not None and (
        isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or not 1 <= threads <= _MAX_THREADS
    ):
        raise ValueError(
            f"threads={threads!r}: give between 1 and {_MAX_THREADS} worker threads, or None for one per core"
        )


# As the command line's `--threads`.
_MAX_THREADS = 256


def _run(
    pipeline: "_core.Pipeline",
    arr: np.ndarray,
    index: pd.Index | None,
    crs: Any,
    *,
    candidates: bool,
    explode: bool | None,
    threads: int | None,
    exchange: str,
    output: str,
    attributes: pd.DataFrame | None = None,
    geometry_name: str = "geometry",
    extra: Mapping[str, Any] | None = None,
    with_done: bool = False,
):
    import geopandas as gpd

    _check_call(crs, threads)
    t0 = time.perf_counter()
    arr, repaired, t_valid = _prepare(arr, pipeline.make_valid)
    payload = _encode(arr, exchange)
    t1 = time.perf_counter()
    done = _core.Pipeline.run(
        pipeline,
        payload,
        fids=_fids(index, len(arr)),
        repaired=repaired,
        candidates=candidates,
        explode=explode,
        threads=threads,
        output=output,
        proj=_proj_of(crs),
        **(extra or {}),
    )
    t2 = time.perf_counter()
    rows = done["row"]
    layer = "candidates" if candidates else "skeletons"
    if index is None:
        index = pd.RangeIndex(len(arr))
    out_index = index if done["in_order"] else index.take(rows)
    reals = done["reals"]
    tool: dict[str, Any] = {name: _column(kind, values, reals) for name, kind, values in done["columns"]}
    tool["rejected"] = _strings(*done["rejected"])
    if attributes is not None and len(attributes.columns) and _core.columns(layer, False)[1]:
        frame = pd.DataFrame(tool, index=out_index)
        # Source fields first, renamed where they clash with the tool's (as the writer does).
        connect = "connect" in (extra or {})
        source = _renamed(attributes.iloc[rows], _reserved(pipeline, connect=connect, explode=explode))
        source.index = out_index
        frame = pd.concat([source, frame], axis=1)
        frame = gpd.GeoDataFrame(
            frame,
            geometry=gpd.GeoSeries(_decode(done["geometry"]), index=out_index, crs=crs),
            crs=crs,
        )
    else:
        # The geometry array with its CRS in the columns: a third of the
        # fixed cost of a GeoDataFrame made from a frame and a GeoSeries.
        # Shapely geometries or None from shapely itself: no need for
        # from_shapely's check of every element.
        tool["geometry"] = gpd.array.GeometryArray(_decode(done["geometry"]), crs=crs)
        frame = _geo_frame(tool, out_index, reals)
    if geometry_name != "geometry":
        frame = frame.rename_geometry(geometry_name)
    t3 = time.perf_counter()
    frame.attrs["skeletonise"] = {
        "pipeline": pipeline.name,
        "tool_version": __version__,
        "counts": dict(done["counts"]),
        "timings": {
            "make_valid_s": t_valid,
            "to_rust_s": t1 - t0 - t_valid,
            **done["timings"],
            "from_rust_s": t3 - t2,
            "total_s": t3 - t0,
        },
        "exchange": "wkb" if isinstance(payload, list) else "geoarrow",
    }
    return (frame, done) if with_done else frame


def skeletonise(
    geometries: Any,
    *,
    methods: Sequence[str] | None = None,
    reference: str | None = None,
    densify: Mapping[str, float] | None = None,
    max_points: int | None = None,
    arc_tolerance: Mapping[str, float] | None = None,
    make_valid: bool | None = None,
    min_area: float | None = None,
    prune: StepOption = True,
    extend: StepOption = True,
    score: StepOption = True,
    select: StepOption = True,
    candidates: bool = False,
    explode: bool = False,
    on_error: str = "reject",
    threads: int | None = None,
    exchange: str = "wkb",
    output: str = "geoarrow",
):
    """Skeletonises every polygon of ``geometries``.

    Parameters
    ----------
    geometries
        A GeoSeries, a GeoDataFrame (its active geometry), a shapely array or a
        list of shapely geometries, in a projected CRS (radii and scores are in
        CRS units).
    methods, reference, densify, max_points, arc_tolerance
        The ``skeleton`` step's options, as in the pipeline file; ``None`` is
        the file's default (``methods=["MA", "StSk", "DVD", "CDT", "VD"]``,
        ``reference="MA"``, ``densify={"factor": 4}``, ``max_points=2_000_000``,
        ``arc_tolerance={"relative": 0.001}``).
    make_valid, min_area
        The ``prepare`` step's options (defaults ``True`` and ``0``).
    prune, extend, score, select
        Each step's options as a mapping with the pipeline file's keys and
        defaults (``prune={"mode": "trunk"}``, ``select={"by": "deviation"}``),
        a string for the step's main key (``prune="trunk"``, ``extend="ray"``,
        ``select="deviation"``), ``True`` for the step with its defaults (the
        default for all four) or ``False`` to leave the step out.
    candidates
        Every method's row (the ``candidates`` layer: ``chosen``, ``legs_raw``,
        ``error``) instead of the chosen one's.
    explode
        One row per polygon part (``polygon_part``), the index repeated.
    on_error
        ``reject`` (a row with the reason in ``rejected``) or ``fail`` (raise
        :class:`RejectedError` at the first rejected feature).
    threads
        Worker threads: ``None`` one per core, ``n`` a pool of ``n`` threads for
        this call (``1`` on a Dask worker, where Dask runs the partitions in
        parallel: one core per task, the methods of a polygon included).
    exchange, output
        How geometries cross to Rust (``wkb``, the faster, or ``geoarrow`` ragged
        arrays of polygons) and back (``geoarrow`` buffers, the faster, or
        ``wkb``). For measurements: the results are the same.

    Returns
    -------
    geopandas.GeoDataFrame
        One row per input geometry (per polygon part with ``explode``; per
        method with ``candidates``), with the input's index and CRS and the
        columns of the command line's ``skeletons`` (or ``candidates``) layer,
        then ``rejected`` and the skeleton (MULTILINESTRING) as geometry.
        ``src_fid`` is the index where it is an integer index, else the
        position. ``frame.attrs["skeletonise"]`` holds counts and timings.

    Raises
    ------
    PipelineError
        An invalid option, with the command line's message.
    RejectedError
        A rejected feature under ``on_error="fail"``.
    """
    pipeline = _options_pipeline(
        make_valid=make_valid,
        min_area=min_area,
        skeleton={
            "methods": methods,
            "reference": reference,
            "densify": densify,
            "max_points": max_points,
            "arc_tolerance": arc_tolerance,
        },
        steps={"prune": prune, "extend": extend, "score": score, "select": select},
        on_error=on_error,
    )
    arr, index, crs = _geometry_array(geometries)
    return _run(
        pipeline,
        arr,
        index,
        crs,
        candidates=candidates,
        explode=explode,
        threads=threads,
        exchange=exchange,
        output=output,
    )


_PIPELINES: dict[tuple[str, float, tuple[str, ...]], "_core.Pipeline"] = {}


def _load(pipeline: Union[str, os.PathLike, "_core.Pipeline"], overrides: Sequence[str]) -> "_core.Pipeline":
    if isinstance(pipeline, _core.Pipeline):
        return pipeline
    path = os.fspath(pipeline)
    key = (os.path.abspath(path), os.stat(path).st_mtime if os.path.exists(path) else 0.0, tuple(overrides))
    if key not in _PIPELINES:
        _PIPELINES[key] = _core.Pipeline.load(path, list(overrides))
    return _PIPELINES[key]


def load_pipeline(path: Union[str, os.PathLike], overrides: Sequence[str] = ()) -> "_core.Pipeline":
    """Loads and validates a pipeline file once (to pass to :func:`apply` many times)."""
    return _core.Pipeline.load(os.fspath(path), list(overrides))


def apply(
    gdf,
    pipeline: Union[str, os.PathLike, "_core.Pipeline"],
    *,
    overrides: Sequence[str] = (),
    candidates: bool = False,
    threads: int | None = None,
):
    """Runs the steps of a pipeline file on a GeoDataFrame.

    The file is validated as ``skeletonise validate`` does, with the same
    messages; its ``input`` and ``output`` sections may be left out and are
    not used, except ``output.explode`` (one row per polygon part) and
    ``on_error``. ``overrides`` are ``--set`` style ``KEY=VALUE`` strings.

    Returns a GeoDataFrame with the input's index, its columns (renamed
    ``src_<name>`` where they clash with the tool's, as in the GeoPackage),
    the columns of the ``skeletons`` layer, ``rejected`` and the skeleton in
    place of the input's geometry (same column name, same CRS). With
    ``candidates=True``, the ``candidates`` layer instead: every method's row
    (without the input's columns, as in the GeoPackage).

    For Dask-GeoPandas, ``ddf.map_partitions(skeletonise.apply, "file.yaml",
    threads=1, meta=...)``: see ``examples/dask_islands.py``.
    """
    _need_geo()
    p = _load(pipeline, overrides)
    if p.partition:
        raise PipelineError(
            "the `partition` step reads the coverage of `input.neighbours` and writes it grown once every "
            "polygon is done, which one GeoDataFrame cannot hold: run it with skeletonise.apply_layers(gdf, "
            "pipeline, neighbours=units), the command line (`skeletonise run`) or QGIS (skeletonise:partition)"
        )
    if p.collapse:
        raise PipelineError(
            "the `collapse` step writes kept areas beside the lines, which one GeoDataFrame cannot hold: run it "
            "with skeletonise.apply_layers(gdf, pipeline), the command line (`skeletonise run`) or QGIS "
            "(skeletonise:collapse)"
        )
    return _run_frame(gdf, p, candidates=candidates, threads=threads)


def _run_frame(gdf, p: "_core.Pipeline", *, candidates: bool, threads: int | None, **more: Any):
    """``_run`` on a GeoDataFrame: its geometry in, its other columns carried, its geometry's name kept."""
    geometry_name = gdf.geometry.name
    return _run(
        p,
        np.asarray(gdf.geometry.values, dtype=object),
        gdf.index,
        gdf.crs,
        candidates=candidates,
        explode=None,
        threads=threads,
        exchange="wkb",
        output="geoarrow",
        attributes=gdf.drop(columns=[geometry_name]),
        geometry_name=geometry_name,
        **more,
    )


__all__.append("load_pipeline")


def _reserved(
    pipeline: "_core.Pipeline", neighbours: bool = False, connect: bool = False, explode: bool | None = None
) -> list:
    """The tool's column names beside which a source column (of ``input``, or with ``neighbours``
    of ``neighbours``) is renamed in a call of ``pipeline`` (``connect``: lines given; ``explode``
    as the call asks), as the command line's writer renames them; a frame of ``input`` has a
    ``rejected`` column too."""
    names = list(pipeline.reserved(neighbours, connect, explode))
    return names if neighbours else names + ["rejected"]


def _renamed(frame: Any, reserved: Sequence[str]) -> Any:
    """``frame`` with its columns named as the command line's writer names source fields beside
    the tool's columns ``reserved``: ``src_`` repeated until the name is free (``_core.source_names``)."""
    names = _core.source_names([str(c) for c in frame.columns], list(reserved))
    return frame.set_axis([c if str(c) == n else n for c, n in zip(frame.columns, names)], axis=1)


def _side_input(gdf, crs: Any, what: str) -> tuple[list, np.ndarray]:
    """A second input (``connect`` lines, ``neighbours`` polygons) as WKB in ``crs``, with its FIDs
    (the index when it is an integer index, as pyogrio's ``fid_as_index`` gives them)."""
    series = gdf.geometry if hasattr(gdf, "geometry") else gdf
    if crs is not None and getattr(series, "crs", None) is not None and series.crs != crs:
        series = series.to_crs(crs)
    arr = np.asarray(series.values, dtype=object)
    if len(arr) == 0:
        raise PipelineError(f"`{what}` has no features")
    return _encode(arr, "wkb"), _fids(series.index, len(arr))


def _layer_frame(layer: dict, crs: Any, sources: Mapping[str, Any], reserved: Mapping[str, list]) -> Any:
    """A GeoDataFrame of one of the result's ``layers``: the fields of the frame it carries
    (``input`` or ``neighbours``, joined by ``src_fid``), then its own columns, then its geometry."""
    import geopandas as gpd

    tool = {name: _column(kind, values, layer["reals"]) for name, kind, values in layer["columns"]}
    frame = pd.DataFrame(tool)
    carried = sources.get(layer["fields"]) if layer["fields"] else None
    if carried is not None and "src_fid" in frame and len(carried.columns):
        by_fid = pd.Series(np.arange(len(carried)), index=_fids(carried.index, len(carried)))
        at = by_fid.reindex(frame["src_fid"].astype("Int64").to_numpy(na_value=-1)).to_numpy()
        own = carried.iloc[np.where(np.isnan(at), 0, at).astype(np.int64)].reset_index(drop=True)
        own.loc[np.isnan(at)] = None
        own = _renamed(own, reserved[layer["fields"]])
        frame = pd.concat([own, frame], axis=1)
    geometry = [None if g is None else shapely.from_wkb(g) for g in layer["geometry"][1]]
    return gpd.GeoDataFrame(frame, geometry=gpd.GeoSeries(geometry, crs=crs), crs=crs)


def apply_layers(
    gdf,
    pipeline: Union[str, os.PathLike, "_core.Pipeline"],
    *,
    overrides: Sequence[str] = (),
    connect=None,
    snap: float = 0.0,
    neighbours=None,
    neighbour_snap: float | None = None,
    candidates: bool = False,
    threads: int | None = None,
    sides: Mapping[str, Any] | None = None,
) -> dict:
    """Runs the steps of a pipeline file on a GeoDataFrame, every layer of the output included:
    the function for pipelines with the ``collapse`` or ``partition`` step, which :func:`apply`
    refuses (their layers do not fit in one frame).

    Returns a dict of GeoDataFrames by the GeoPackage's layer names — the layers and columns the
    command line writes for the same pipeline file (its plan), but ``rejected`` (the skeleton
    frame's ``rejected`` column), bars, widths and the run record: ``skeletons`` (as
    :func:`apply` returns it), ``candidates`` with ``candidates=True``, and the steps' layers —
    ``areas`` (the kept areas of ``collapse``; a partition's remainders), ``coverage`` (the units
    of ``neighbours`` grown by what they received, with their columns), ``boundaries`` (the new
    boundaries), ``given`` (what each unit received of each polygon), ``connections`` and
    ``network`` with ``connect``, and a registered step's layers (``labels`` of the ``label``
    step, its ``minzoom`` from ``gdf``'s CRS as on the command line), the rows a step makes after
    the last feature included. ``sides`` gives a registered step's side input layer by the
    step's name (a GeoDataFrame or GeoSeries, reprojected to ``gdf``'s CRS; the pipeline file's
    ``source`` of it is not opened here). ``connect`` (a
    GeoDataFrame or GeoSeries of lines: the line network of ``input.connect``, ``snap`` its snap
    distance) and ``neighbours`` (a GeoDataFrame of polygons: the coverage of
    ``input.neighbours``; ``neighbour_snap`` its ``snap``: unit vertices and edges within it of a
    polygon's bank are moved onto it, default the pipeline file's ``input.neighbours.snap`` or 1e-7 ×
    each polygon's extent) are reprojected to ``gdf``'s CRS when theirs differs; their ``src_fid``
    is their index where it is an integer index (pyogrio's ``fid_as_index=True``), else the
    position. With a ``partition`` step, adjacent polygons of ``gdf`` are merged first, exactly,
    as the command line's reader merges them (the skeleton row takes the index of the member
    with the smallest FID).
    """
    _need_geo()
    p = _load(pipeline, overrides)
    extra: dict[str, Any] = {}
    if connect is not None:
        lines, fids = _side_input(connect, gdf.crs, "connect")
        extra.update(connect=lines, connect_fids=fids.tolist(), snap=float(snap))
    units = None
    if neighbours is not None:
        units, fids = _side_input(neighbours, gdf.crs, "neighbours")
        extra.update(neighbours=units, neighbour_fids=fids.tolist())
        if neighbour_snap is not None:
            extra["neighbour_snap"] = float(neighbour_snap)
    if candidates:
        extra["with_candidates"] = True
    if sides:
        given = {name: _side_input(layer, gdf.crs, f"sides[{name!r}]") for name, layer in sides.items()}
        extra["sides"] = {name: (wkbs, fids.tolist()) for name, (wkbs, fids) in given.items()}
    frame, done = _run_frame(gdf, p, candidates=False, threads=threads, extra=extra, with_done=True)
    sources: dict[str, Any] = {"input": gdf.drop(columns=[gdf.geometry.name])}
    if neighbours is not None and hasattr(neighbours, "geometry"):
        sources["neighbours"] = neighbours.drop(columns=[neighbours.geometry.name])
    out = {"skeletons": frame}
    given = connect is not None
    reserved = {"input": _reserved(p, connect=given), "neighbours": _reserved(p, neighbours=True, connect=given)}
    for name, layer in done.get("layers", {}).items():
        out[name] = _layer_frame(layer, gdf.crs, sources, reserved)
    return out


__all__.append("apply_layers")


def labels(
    geometries: Any,
    *,
    smooth: float | None = None,
    margin: float | None = None,
    min_elongation: float | None = None,
    parts: str | None = None,
    min_pixels: float | None = None,
    make_valid: bool = True,
    threads: int | None = None,
):
    """One label per polygon part: the ``label`` step of the command line.

    A smooth line along the medial axis where the part is elongated enough to
    carry a curved name (its axis path at least ``min_elongation`` times its
    largest width), turning by at most ``smooth`` degrees over any stretch one
    local width long and staying within ``1 - margin`` local radii of the
    axis; otherwise the centre of the part's largest inscribed disc (the pole
    of inaccessibility). Holes (islands) are respected.

    It runs the pipeline ``prepare: {make_valid, min_area: 0}``, ``skeleton: {methods: [MA]}``,
    ``label: {...}`` through the same run as :func:`apply_layers` and the command line.

    Parameters
    ----------
    geometries
        A GeoDataFrame, a GeoSeries, a shapely array or a list of polygons,
        in a projected CRS.
    smooth, margin, min_elongation, parts, min_pixels
        The ``label`` step's options, as in the pipeline file (``None``: the
        step's default, as :func:`describe` lists them — smooth 60, margin
        0.9, min_elongation 3, parts ``"each"``, min_pixels 64): ``parts`` is
        ``"each"`` (every polygon part its label) or ``"largest"``;
        ``min_pixels`` sets ``minzoom``.
    make_valid
        Repair invalid polygons with GEOS MakeValid first (as the command
        line's ``prepare`` step does by default); of a repaired geometry the
        polygons are labelled, as on the command line (a spike that MakeValid
        turns into a line is left out, not a reason to reject the feature).
    threads
        Worker threads (``None``: one per core).

    Returns a GeoDataFrame with one row per labelled part: the input's index
    (repeated for the parts of a multipolygon), a GeoDataFrame's own columns
    (renamed ``src_<name>`` where the command line renames them),
    ``polygon_part``, ``kind`` (``line``, ``point``, or ``none`` for a part
    thinner than the axis's grid), ``length``, ``max_width`` (2r),
    ``elongation``, ``minzoom`` (the smallest web-map zoom at which the line
    is ``min_pixels`` long, or a point's disc that wide, at the label's
    latitude; NA without a CRS) and ``rejected`` (why a feature has no label:
    NULL, not a polygon, invalid, no medial axis), and the label as geometry
    (same CRS). Every input row gives at least one output row.
    """
    import geopandas as gpd

    doc = {
        "steps": [
            {"prepare": {"make_valid": bool(make_valid), "min_area": 0.0}},
            {"skeleton": {"methods": ["MA"]}},
            {"label": {k: v for k, v in (("smooth", smooth), ("margin", margin), ("min_elongation", min_elongation),
                                         ("parts", parts), ("min_pixels", min_pixels)) if v is not None}},
        ]
    }
    try:
        p = _core.Pipeline.from_options(json.dumps(doc, default=_json_default), "labels()")
    except PipelineError as e:
        raise PipelineError(str(e).replace("steps[2].label.", "")) from None
    arr, index, crs = _geometry_array(geometries)
    frame, done = _run(p, arr, index, crs, candidates=False, explode=False, threads=threads,
                       exchange="wkb", output="wkb", with_done=True)
    n = len(arr)
    index = index if index is not None else pd.RangeIndex(n)
    layer = done.get("layers", {}).get("labels")
    own = _layer_frame(layer, crs, {}, {}) if layer is not None else gpd.GeoDataFrame(geometry=[], crs=crs)
    by_fid = pd.Series(np.arange(n), index=_fids(index, n))
    at = by_fid.reindex(own["src_fid"].astype("Int64").to_numpy(na_value=-1)).to_numpy().astype(np.int64)
    own = own.drop(columns=["src_fid"])
    own["rejected"] = pd.array([None] * len(own), dtype="string")
    # A rejected feature: one row with the reason (the skeleton frame's rows are in input order).
    bad = frame["rejected"].notna().to_numpy()
    rows = np.asarray(done["row"], dtype=np.int64)[bad]
    lost = gpd.GeoDataFrame({"rejected": frame["rejected"].to_numpy()[bad]}, geometry=[None] * len(rows), crs=crs)
    both = pd.concat([own.reset_index(drop=True), lost.reset_index(drop=True)], ignore_index=True)
    position = np.concatenate([at, rows])
    order = np.argsort(position, kind="stable")
    both = both.iloc[order].reset_index(drop=True)
    position = position[order]
    tool = {
        "polygon_part": both["polygon_part"].astype("Int32").array,
        "kind": both["kind"].astype("string").array,
        "length": both["length"].astype("Float64").array,
        "max_width": both["max_width"].astype("Float64").array,
        "elongation": both["elongation"].astype("Float64").array,
        "minzoom": both["minzoom"].astype("Int32").array,
        "rejected": both["rejected"].astype("string").array,
    }
    columns: dict[str, Any] = {}
    if isinstance(geometries, gpd.GeoDataFrame):
        source = _renamed(geometries.drop(columns=[geometries.geometry.name]), _reserved(p) + ["geometry"])
        columns = {c: source[c].array.take(position) for c in source.columns}
    columns.update(tool)
    columns["geometry"] = gpd.array.GeometryArray(np.asarray(both.geometry.values, dtype=object), crs=crs)
    return _geo_frame(columns, index.take(position))


__all__.append("labels")
