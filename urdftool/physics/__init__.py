"""Physics helpers: rigid-body inertia (pure Python, ``inertia``), mesh mass properties
(trimesh, imported lazily, ``meshes``) and the per-link analysis the ``inertia`` rules and the
``inertia`` command share (``links``).

Nothing here imports numpy or trimesh at module level: ``check`` on a robot made of boxes,
cylinders and spheres runs without them.
"""
