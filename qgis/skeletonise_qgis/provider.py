"""The `skeletonise` Processing provider."""

import os

from qgis.core import QgsProcessingProvider
from qgis.PyQt.QtGui import QIcon


class SkeletoniseProvider(QgsProcessingProvider):
    """Polygons to skeletons, label lines and pipeline files, run by the skeletonise wheel in-process."""

    def id(self):
        return "skeletonise"

    def name(self):
        return "Skeletonise"

    def longName(self):  # noqa: N802
        from . import bridge

        version = bridge.version()
        if version is None:
            return "Skeletonise (the skeletonise Python package is missing: see an algorithm's message)"
        return f"Skeletonise {version}{' (bundled)' if bridge.bundled() else ''}"

    def icon(self):
        return QIcon(os.path.join(os.path.dirname(__file__), "icon.svg"))

    def loadAlgorithms(self):  # noqa: N802
        from .algorithms import ALGORITHMS

        for algorithm in ALGORITHMS:
            self.addAlgorithm(algorithm())
