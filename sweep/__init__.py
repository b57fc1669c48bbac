"""Design sweeps without Blender: many variants of one propeller, wind-blade or impeller
definition, each built, written as IGES and measured, on Dask (issue 23).

- :mod:`.spec`: the sweep file (base definition, named parameters, design), the variants
  it makes and their keys (a hash of each variant's definition and settings);
- :mod:`.variant`: one variant built, written and measured (plain data in, plain data
  out; imports only ``geometry/`` and ``iges/``), and the check that its outputs exist
  and verify, which is what makes a sweep resumable;
- :mod:`.runner` and ``python scripts/sweep.py``: the sweep on a Dask cluster, the
  progress bar and the metrics table (Parquet and CSV). Dask and pyarrow are imported
  there only: they are dependencies of the sweep command, never of the Blender extension.

Nothing here imports bpy. The Blender side (loading one variant's definition into the
scene) is ``operators/sweep_variant.py``, which reads a sweep folder with :mod:`.folder`.
"""
