"""What geobrep's own plugins register, as plain data: discovery reads it, imports nothing.

Each built-in entry point (``[project.entry-points."geobrep.plugins"]`` of geobrep's
``pyproject.toml``) is declared here with its module and the items its hooks register: the
kind and name of each, and for a format what choosing a reader or writer needs (extensions,
whether it reads, writes and sniffs, whether its content is generic). The loader fills the
registries with these declarations and imports a plugin's module only when one of its items
is used (:meth:`geobrep.host.loader.PluginHost.materialize`): ``import geobrep``, ``geobrep
--help`` and reading a .ts load none of the other plugins. ``tests/plugins/
test_plugin_declarations.py`` checks every declaration against what the plugin's hooks
register when it is imported, so the two cannot drift.

Third-party plugins declare nothing here: they are imported at discovery, as before.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["BUILTIN_PLUGINS", "Declared"]


@dataclass(frozen=True)
class Declared:
    """One item a built-in plugin registers: its registry (``"formats"``, ``"clippers"``, ...),
    its name and, for a format, what reader and writer choice needs before the import."""

    kind: str
    name: str
    extensions: tuple[str, ...] = ()
    reads: bool = False
    writes: bool = False
    sniffs: bool = False
    generic_content: bool = False


def _format(name: str, extensions: tuple[str, ...], **flags: bool) -> Declared:
    return Declared("formats", name, extensions, **flags)


#: Entry-point name -> (the module it names, what its hooks register).
BUILTIN_PLUGINS: dict[str, tuple[str, tuple[Declared, ...]]] = {
    "blocks": (
        "geobrep.plugins.blocks",
        (Declared("builders", "blocks"),),
    ),
    "checks": (
        "geobrep.plugins.checks",
        (
            Declared("checks", "arc_ends"),
            Declared("checks", "arc_patch_order"),
            Declared("checks", "block_closure"),
            Declared("checks", "block_orientation"),
            Declared("checks", "colocated_vertices"),
            Declared("checks", "degenerate_elements"),
            Declared("checks", "duplicated_elements"),
            Declared("checks", "gaps"),
            Declared("checks", "inconsistent_orientation"),
            Declared("checks", "inverted_tets"),
            Declared("checks", "isolated_vertices"),
            Declared("checks", "non_manifold_edges"),
            Declared("checks", "non_manifold_vertices"),
            Declared("checks", "patch_boundaries"),
            Declared("checks", "patch_sides"),
            Declared("checks", "polyline_intersections"),
            Declared("checks", "region_sides"),
            Declared("checks", "self_intersections"),
            Declared("checks", "surface_intersections"),
            Declared("checks", "t_junctions"),
            Declared("checks", "universe_closure"),
            Declared("checks", "volume_balance"),
        ),
    ),
    "clip": (
        "geobrep.plugins.clip",
        (
            Declared("clippers", "annotation"),
            Declared("clippers", "block"),
            Declared("clippers", "nurbs"),
            Declared("clippers", "octree"),
            Declared("clippers", "pointset"),
            Declared("clippers", "polygon"),
            Declared("clippers", "polyline"),
            Declared("clippers", "regular_grid"),
            Declared("clippers", "structured_grid"),
            Declared("clippers", "surface"),
            Declared("clippers", "well"),
        ),
    ),
    "csv": (
        "geobrep.adapters.csv",
        (_format("csv", (".csv",), reads=True, writes=True, sniffs=True, generic_content=True),),
    ),
    "eclipse": (
        "geobrep.adapters.eclipse",
        (_format("grdecl", (".grdecl",), reads=True, writes=True, sniffs=True),),
    ),
    "fit": (
        "geobrep.plugins.fit",
        (
            Declared("fitters", "approximation"),
            Declared("fitters", "hybrid"),
            Declared("fitters", "kriging"),
            Declared("fitters", "skinning"),
        ),
    ),
    "geoh5": (
        "geobrep.adapters.geoh5",
        (_format("geoh5", (".geoh5",), reads=True, writes=True),),
    ),
    "gis": (
        "geobrep.adapters.gis",
        (
            _format("geojson", (".geojson",), reads=True, writes=True, sniffs=True),
            _format("geotiff", (".tif", ".tiff"), reads=True, writes=True, sniffs=True),
            _format("gpkg", (".gpkg",), reads=True, writes=True, sniffs=True),
            _format("shapefile", (".shp",), reads=True, writes=True),
        ),
    ),
    "gltf": (
        "geobrep.adapters.gltf",
        (
            _format("3dtiles", (".json",), reads=True, writes=True, sniffs=True),
            _format("gltf", (".glb",), reads=True, writes=True, sniffs=True),
        ),
    ),
    "gocad": (
        "geobrep.adapters.gocad",
        (
            _format(
                "gocad",
                (".ts", ".pl", ".vs", ".so", ".ml", ".gp", ".vo", ".sg", ".wl"),
                reads=True,
                writes=True,
                sniffs=True,
            ),
            _format("skua", (".xml",), reads=True, writes=True, sniffs=True),
        ),
    ),
    "html": (
        "geobrep.adapters.html",
        (_format("html", (".html", ".htm"), writes=True),),
    ),
    "meshio": (
        "geobrep.adapters.meshio",
        (
            _format("gmsh", (".msh",), reads=True, writes=True, sniffs=True),
            _format("obj", (".obj",), reads=True, writes=True),
            _format("off", (".off",), reads=True, writes=True, sniffs=True),
            _format("stl", (".stl",), reads=True, writes=True, sniffs=True),
            _format("vtk", (".vtk",), reads=True, writes=True, sniffs=True),
            _format("vtu", (".vtu",), reads=True, writes=True, sniffs=True),
        ),
    ),
    "native": (
        "geobrep.adapters.native",
        (_format("native", (".geobrep",), reads=True, writes=True, sniffs=True),),
    ),
    "omf": (
        "geobrep.adapters.omf",
        (_format("omf", (".omf",), reads=True, writes=True, sniffs=True),),
    ),
    "open3d": (
        "geobrep.adapters.open3d",
        (),
    ),
    "ply": (
        "geobrep.adapters.ply",
        (_format("ply", (".ply",), reads=True, writes=True, sniffs=True),),
    ),
    "pyvista": (
        "geobrep.adapters.pyvista",
        (
            _format("png", (".png",), writes=True),
            _format("vtp", (".vtp",), reads=True, writes=True, sniffs=True),
        ),
    ),
    "resqml": (
        "geobrep.adapters.resqml",
        (_format("resqml", (".epc",), reads=True, writes=True, sniffs=True),),
    ),
    "voxelize": (
        "geobrep.plugins.voxelize",
        (Declared("voxelizers", "voxelize"),),
    ),
    "wells": (
        "geobrep.adapters.wells",
        (
            _format("deviation", (".dev",), reads=True, writes=True),
            _format("las", (".las",), reads=True, writes=True, sniffs=True),
        ),
    ),
}
