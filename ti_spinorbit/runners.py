"""Where an ensemble runs: in this process, or in chunks on a Dask cluster.

Both runners take the same member table (:class:`ti_spinorbit.members.Members`), built once
by the same checks (``section.section_inputs``):

* the local runner, :func:`ti_spinorbit.section.section_of`: one ensemble launch here;
* the Dask runner, :func:`ti_spinorbit.distributed.run_members`: the table cut into chunks,
  one per task, joined in member order, bit for bit the local result.

:func:`run_section` chooses between them by ``client``; the maps and scans call it, so a
local run never imports the Dask module (it is imported with a client only).
"""

from . import section


def check_client(client):
    """``client`` if it is a ``dask.distributed.Client`` (or None), else a one-line TypeError
    naming what was given: raised before any work, not as an AttributeError from inside the
    run (``client.nthreads``, ``client.submit``)."""
    if client is None:
        return None
    try:
        from distributed import Client          # Dask: optional, imported with a client only
    except ImportError:
        Client = None
    if Client is not None and isinstance(client, Client):
        return client
    hint = "" if Client is not None else \
        " (dask is not installed: pip install ti-spinorbit[dask])"
    raise TypeError(f"client must be a dask.distributed.Client or None, not "
                    f"{type(client).__name__}{hint}")


def run_section(client, system, theta_p, thetadot_p, orbits, chunk_size=None,
                **options) -> section.SectionResult:
    """A surface of section (``options``: :func:`~ti_spinorbit.section.surface_of_section`'s
    keywords) on the local runner when ``client`` is None, else on the cluster behind it in
    chunks of ``chunk_size`` members (default: a few chunks per worker); the same result."""
    check_client(client)
    if client is None:
        return section.surface_of_section(system, theta_p, thetadot_p, orbits, **options)
    from . import distributed                    # Dask: imported with a client only

    progress = options.pop("progress", None)
    return distributed.run_sections(client, system, theta_p, thetadot_p, orbits,
                                    chunk_size=chunk_size, progress=progress, **options)


__all__ = ["run_section", "check_client"]
