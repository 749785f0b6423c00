"""The skeletonise QGIS plugin: a Processing provider over the skeletonise Python wheel."""


def classFactory(iface):  # noqa: N802 - the name QGIS looks for
    """QGIS's entry point: the plugin object."""
    from .plugin import SkeletonisePlugin

    return SkeletonisePlugin(iface)
