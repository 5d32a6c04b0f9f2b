"""Scene understanding: what the robot can say about a scene before any learning.

The rules that read a scene's poses and point cloud directly, between the data model and
the parts that learn, reason and simulate:

- :mod:`~unstack.understanding.plausibility`: whether a scene could be a real pile (boxes
  inside one another, floating, far outside a container), as warnings or refusals;
- :mod:`~unstack.understanding.statics`: a box that cannot stand on its own base leans on
  a neighbour, whose support probability is raised;
- :mod:`~unstack.understanding.hidden_load`: the undetected load the cloud shows on each
  detected box;
- :mod:`~unstack.understanding.clouds`: point clouds sampled from box surfaces, and varied
  as another sensor would see them;
- :mod:`~unstack.understanding.detector`: the poses a box detector with errors reports.

The recipe that turns a scene into support probabilities with a learned model
(:mod:`unstack.pipeline`) uses these; the reasoner never does.

Examples
--------
>>> from unstack.scene import load_scene
>>> from unstack.understanding.hidden_load import hidden_load
>>> hidden_load(load_scene("examples/pile5.scene.json")).round(2).tolist()
[2.41, 2.03, 2.73, 1.01, 1.7]
"""

__all__ = ["clouds", "detector", "hidden_load", "plausibility", "statics"]
