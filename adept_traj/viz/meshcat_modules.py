"""meshcat, imported in one place for every module of :mod:`adept_traj.viz`.

meshcat 0.3.2 imports pyzmq's deprecated ``zmq.eventloop.ioloop``; its deprecation warning
is silenced here, once, and the viewer modules take meshcat and the parts of it they use
(geometry, animation, paths, the viewer window, its message packer ``umsgpack``) from this
module.
"""

from __future__ import annotations

import warnings

with warnings.catch_warnings():
    warnings.filterwarnings("ignore", "zmq.eventloop.ioloop is deprecated", DeprecationWarning)
    import meshcat
    import meshcat.geometry as mg
    import umsgpack
    from meshcat.animation import Animation, AnimationFrameVisualizer
    from meshcat.path import Path as MeshcatPath
    from meshcat.visualizer import ViewerWindow

__all__ = [
    "Animation",
    "AnimationFrameVisualizer",
    "MeshcatPath",
    "ViewerWindow",
    "meshcat",
    "mg",
    "umsgpack",
]
