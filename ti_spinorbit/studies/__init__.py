"""What the science asks for: surfaces of section and time series (with their local and Dask
runners), chaos and parameter maps, resonance-overlap scans, libration amplitudes, section
classification and kernel warm-up. Built on ``engine``; never imports ``output``: a result's
``plot`` finds its figure through the registry that ``output.plotting`` fills.
"""
