"""Registers the `skeletonise` Processing provider (also in `qgis_process`, which calls initProcessing)."""

from qgis.core import QgsApplication


class SkeletonisePlugin:
    """The plugin: it only adds the Processing provider."""

    def __init__(self, iface):
        self.iface = iface
        self.provider = None

    def initProcessing(self):  # noqa: N802
        from .provider import SkeletoniseProvider

        self.provider = SkeletoniseProvider()
        QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self):  # noqa: N802
        self.initProcessing()

    def unload(self):
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
