"""Write the small intersphinx inventories of docs/_intersphinx/ (run after changing NAMES).

The documentation is built where nothing outside a package registry can be reached (CI, the
build machines), so Sphinx's intersphinx cannot download each project's ``objects.inv``.
Instead docs/conf.py points intersphinx at these files: one inventory per project, listing
only the external names the site refers to, each with its real address on that project's
documentation site. They are written in Sphinx's own inventory format (version 2: a
four-line header, then zlib-compressed lines ``name domain:role priority uri display``,
where ``$`` in the uri stands for the name), so intersphinx reads them like the downloaded
ones. A reference to a name missing here fails the nitpicky build (warnings are errors):
add the name below, rerun ``python docs/_intersphinx/make_inventories.py`` and commit the
``.inv`` files.
"""

import zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent

# project -> (documentation root, version, [(name, domain:role, uri relative to the root)])
NAMES = {
    "python": ("https://docs.python.org/3/", "3", [
        ("argparse", "py:module", "library/argparse.html#module-argparse"),
        ("argparse.ArgumentParser", "py:class", "library/argparse.html#$"),
        ("dataclasses.dataclass", "py:function", "library/dataclasses.html#$"),
        ("dataclasses.field", "py:function", "library/dataclasses.html#$"),
        ("dataclasses.fields", "py:function", "library/dataclasses.html#$"),
        ("doctest", "py:module", "library/doctest.html#module-doctest"),
        ("enum.IntEnum", "py:class", "library/enum.html#$"),
        ("FileNotFoundError", "py:exception", "library/exceptions.html#$"),
        ("KeyboardInterrupt", "py:exception", "library/exceptions.html#$"),
        ("RuntimeWarning", "py:exception", "library/exceptions.html#$"),
        ("TypeError", "py:exception", "library/exceptions.html#$"),
        ("UserWarning", "py:exception", "library/exceptions.html#$"),
        ("ValueError", "py:exception", "library/exceptions.html#$"),
        ("float", "py:class", "library/functions.html#$"),
        ("int", "py:class", "library/functions.html#$"),
        ("str", "py:class", "library/stdtypes.html#$"),
        ("dict", "py:class", "library/stdtypes.html#$"),
        ("list", "py:class", "library/stdtypes.html#$"),
        ("tuple", "py:class", "library/stdtypes.html#$"),
        ("os.replace", "py:function", "library/os.html#$"),
        ("pathlib.Path", "py:class", "library/pathlib.html#$"),
        ("warnings.warn", "py:function", "library/warnings.html#$"),
    ]),
    "numpy": ("https://numpy.org/doc/stable/", "2", [
        ("numpy.ndarray", "py:class", "reference/generated/numpy.ndarray.html#$"),
        ("numpy.load", "py:function", "reference/generated/numpy.load.html#$"),
        ("numpy.savez_compressed", "py:function",
         "reference/generated/numpy.savez_compressed.html#$"),
        ("numpy.linspace", "py:function", "reference/generated/numpy.linspace.html#$"),
        ("numpy.nan", "py:data", "reference/constants.html#$"),
        ("numpy.lib.npyio.NpzFile", "py:class",
         "reference/generated/numpy.lib.npyio.NpzFile.html#$"),
    ]),
    "matplotlib": ("https://matplotlib.org/stable/", "3", [
        ("matplotlib.axes.Axes", "py:class", "api/_as_gen/matplotlib.axes.Axes.html#$"),
        ("matplotlib.figure.Figure", "py:class", "api/_as_gen/matplotlib.figure.Figure.html#$"),
        ("matplotlib.pyplot.subplots", "py:function",
         "api/_as_gen/matplotlib.pyplot.subplots.html#$"),
        ("matplotlib.pyplot.savefig", "py:function",
         "api/_as_gen/matplotlib.pyplot.savefig.html#$"),
        ("matplotlib.colors.Colormap", "py:class",
         "api/_as_gen/matplotlib.colors.Colormap.html#$"),
        ("matplotlib.use", "py:function", "api/matplotlib_configuration_api.html#$"),
    ]),
    "xarray": ("https://docs.xarray.dev/en/stable/", "2023", [
        ("xarray.Dataset", "py:class", "generated/xarray.Dataset.html#$"),
        ("xarray.DataArray", "py:class", "generated/xarray.DataArray.html#$"),
        ("xarray.Dataset.sel", "py:method", "generated/xarray.Dataset.sel.html#$"),
    ]),
    "astropy": ("https://docs.astropy.org/en/stable/", "5", [
        ("astropy.units", "py:module", "units/index.html#module-astropy.units"),
        ("astropy.units.Quantity", "py:class", "api/astropy.units.Quantity.html#$"),
        ("astropy.units.Unit", "py:class", "api/astropy.units.Unit.html#$"),
    ]),
    "dask": ("https://docs.dask.org/en/stable/", "2023", [
        ("dask", "py:module", "index.html"),
    ]),
    "distributed": ("https://distributed.dask.org/en/stable/", "2023", [
        ("distributed.Client", "py:class", "api.html#$"),
        ("dask.distributed.Client", "py:class", "api.html#distributed.Client"),
        ("distributed.LocalCluster", "py:class", "api.html#$"),
    ]),
}


def inventory(project, version, entries):
    """The bytes of an objects.inv (format version 2) for these entries."""
    header = (f"# Sphinx inventory version 2\n# Project: {project}\n# Version: {version}\n"
              "# The remainder of this file is compressed using zlib.\n").encode()
    body = "".join(f"{name} {role} 1 {uri} -\n" for name, role, uri in sorted(entries))
    return header + zlib.compress(body.encode())


def main():
    for project, (_root, version, entries) in NAMES.items():
        (HERE / f"{project}.inv").write_bytes(inventory(project, version, entries))
        print(f"{project}.inv: {len(entries)} names")


if __name__ == "__main__":
    main()
