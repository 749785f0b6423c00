"""Type stubs of the Rust extension ``skeletonise._core`` (built by maturin)."""

from os import PathLike
from typing import Any, Literal, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

class PipelineError(ValueError):
    """An invalid pipeline file or option; the text is the command line's (exit status 78 there)."""

class RejectedError(RuntimeError):
    """A feature was rejected under ``on_error: fail``; the text is the command line's (exit status 65 there)."""

# (type id 3 polygon / 6 multipolygon, coords (n, 2) float64, offsets int64 per level, null mask or None)
Ragged = tuple[int, npt.NDArray[np.float64], list[npt.NDArray[np.int64]], Optional[npt.NDArray[np.bool_]]]

class Cancelled(RuntimeError):
    """A call stopped because its :class:`Cancel` flag was set; nothing of it is returned."""

class Cancel:
    """A cancel flag for :meth:`Pipeline.run`: set from another thread, the call stops before its next feature."""

    def __init__(self) -> None: ...
    def set(self) -> None:
        """Sets the flag."""
    def is_set(self) -> bool:
        """Whether the flag is set."""

class Pipeline:
    """The validated steps of a pipeline, from a file or from keyword options."""

    @staticmethod
    def load(path: Union[str, PathLike[str]], overrides: Sequence[str] = ...) -> Pipeline:
        """Loads and validates a pipeline file (``input`` and ``output`` may be absent); raises PipelineError."""
    @staticmethod
    def from_options(text: str, origin: str) -> Pipeline:
        """Validates a steps document made from keyword options (JSON text); raises PipelineError."""
    def check_inputs(self, *, connect: bool) -> None:
        """Raises PipelineError, with the command line's message, for what the command line refuses
        of the inputs: ``prune: {mode: network}`` without the lines of ``input.connect``
        (``connect``: they are given). ``run`` makes the same check."""
    def reserved(self, neighbours: bool = False, connect: bool = False, explode: Optional[bool] = None) -> list[str]:
        """The names for which a source field is written as ``src_<name>`` by a call of this pipeline
        (every layer of its plan that carries the source's fields, a registered step's too); with
        ``neighbours``, those of a field of the units."""
    @property
    def make_valid(self) -> bool:
        """Whether the ``prepare`` step repairs invalid polygons."""
    @property
    def collapse(self) -> bool:
        """Whether the pipeline has a ``collapse`` step (``run`` then also returns ``areas``)."""
    @property
    def partition(self) -> bool:
        """Whether the pipeline has a ``partition`` step (``run`` then needs ``neighbours``)."""
    @property
    def explode(self) -> bool:
        """One row per polygon part (``output.explode``)."""
    @property
    def on_error(self) -> Literal["reject", "fail"]:
        """``reject`` or ``fail``."""
    @property
    def name(self) -> Optional[str]:
        """The pipeline's name."""
    @property
    def text(self) -> str:
        """The text the pipeline was read from."""
    def run(
        self,
        geometry: Union[list[Optional[bytes]], Ragged],
        *,
        fids: Optional[npt.NDArray[np.int64]] = None,
        repaired: Optional[npt.NDArray[np.bool_]] = None,
        candidates: bool = False,
        explode: Optional[bool] = None,
        threads: Optional[int] = None,
        output: Literal["geoarrow", "wkb"] = "geoarrow",
        cancel: Optional[Cancel] = None,
        connect: Optional[list[Optional[bytes]]] = None,
        connect_fids: Optional[Sequence[int]] = None,
        snap: float = 0.0,
        neighbours: Optional[list[Optional[bytes]]] = None,
        neighbour_fids: Optional[Sequence[int]] = None,
        neighbour_snap: Optional[float] = None,
        with_candidates: bool = False,
        proj: Optional[str] = None,
        sides: Optional[dict[str, tuple[list[bytes | None], Optional[list[int]]]]] = None,
    ) -> dict[str, Any]:
        """Runs the steps with the GIL released.

        Returns ``row`` (the input position of every output row), ``in_order``
        (whether ``row`` is every input position in order), ``columns``
        (``(name, type, values)``; integers as ``(values, null mask)``, texts
        as Arrow large-string buffers ``(offsets, data, null mask or None)``),
        ``rejected`` (reasons, texts as the columns'), ``geometry``
        (``("geoarrow", coords, line_offsets, geom_offsets, null)`` or
        ``("wkb", list)``), ``counts``, ``timings`` and ``layers``: the
        other layers of the steps by name (``areas`` with ``collapse``;
        ``coverage``, ``boundaries``, ``given`` and ``areas`` with
        ``partition``), each ``fields`` (``input``, ``neighbours`` or None:
        whose fields it carries, by ``src_fid``), ``columns``, ``reals`` and
        ``geometry`` as WKB. ``connect`` (WKB lines, FIDs in
        ``connect_fids``) is the line network of ``input.connect``, ``snap``
        its snap distance; ``neighbours`` (WKB polygons, FIDs in
        ``neighbour_fids``) the coverage of ``input.neighbours``.
        ``with_candidates``: the ``candidates`` layer among ``layers`` too,
        from the same pass.
        Raises RejectedError under ``on_error: fail``, Cancelled once
        ``cancel`` is set.
        """

def columns(layer: str, explode: bool = False, collapse: bool = False) -> tuple[list[tuple[str, str]], bool]:
    """The columns of ``skeletons``, ``candidates`` or ``areas`` (a collapse step's) as ``(name, type)``
    (with a collapse step as given), and whether the layer carries the input's attributes; a
    registered step's layers (``coverage``, ``labels``, …): ``Pipeline.layer_columns``."""

def score(
    polygons: list[Optional[bytes]],
    lines: list[Optional[bytes]],
    *,
    fids: Optional[npt.NDArray[np.int64]] = None,
    polygon_keys: Optional[list[Optional[str]]] = None,
    line_keys: Optional[list[Optional[str]]] = None,
    label: str = "external",
    threads: Optional[int] = None,
    output: Literal["geoarrow", "wkb"] = "wkb",
    cancel: Optional[Cancel] = None,
) -> dict[str, Any]:
    """Scores another tool's lines against their polygons (``skeletonise score``): joined by key
    (both key lists) or by location; what ``Pipeline.run`` returns, and ``unjoined`` (why some
    line rows joined no polygon). Raises ValueError when no line joins any polygon."""

def reserved(collapse: bool = False, neighbours: bool = False) -> list[str]:
    """The names for which a source field is written as ``src_<name>`` (in every layer alike), with or without a
    collapse step; with ``neighbours``, those of a field of the units (a pipeline's own: ``Pipeline.reserved``)."""

def source_names(names: list[str], reserved: list[str]) -> list[str]:
    """The names source fields ``names`` are written under beside the tool's columns ``reserved``: ``src_``
    repeated until the name is free, as the command line's writer names them."""

def describe() -> str:
    """The methods and every step's options with their defaults."""

def schema() -> str:
    """The JSON Schema of the pipeline file, as JSON text."""

