"""Running ensembles: the member table, the ensemble launch (the one place that crosses into
the Taichi kernels), host-side kernel evaluations, compile bookkeeping, checkpoints, progress,
memory and cost estimates, the result base classes and registry, the accuracy verdict and the
length-convergence loop. Imports ``model``, ``system``, the kernels and the base modules.
"""
