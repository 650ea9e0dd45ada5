"""The plant's 3-D scene for Foxglove, drawn from its compiled MuJoCo model (any plant with ``model`` and
``data``: no plant is special-cased here).

==================  ========================  ====================================================
topic               schema                    content
==================  ========================  ====================================================
/scene/robot        foxglove.SceneUpdate      one entity per body in the body's frame (``frame_id`` =
                                              body name): its geoms as primitives or a triangle mesh;
                                              a body without a visible geom is drawn as a joint ball
                                              and a stick from its parent. Also the desired
                                              Cartesian path of the trial (world frame). Logged at
                                              each trial's start.
/scene/transforms   foxglove.FrameTransforms  world -> every body frame, per scene frame
/scene/markers      foxglove.SceneUpdate      actual (green) and desired (red) end-effector; each
                                              actuated tendon (a muscle) as a line along its path
                                              coloured by activation, blue (0) to red (1)
/log                foxglove.Log              trial results and plant events, for Foxglove's Log panel
==================  ========================  ====================================================

Frames go into run.mcap every ``recording.scene_every`` control steps (simulated time, so the file is
the same on every machine) and to a live view (``recording/live.py``) at most ``live.display_hz`` times
per wall-clock second. Positions are read from ``MjData`` as the physics left them (read only).
"""

from __future__ import annotations

import time
from typing import Any

import mujoco
import numpy as np

from cerebx.recording.recorder import Recorder, register_schema

PREFIX = "/scene/"
ROBOT, TRANSFORMS, MARKERS, LOG = PREFIX + "robot", PREFIX + "transforms", PREFIX + "markers", "/log"
WORLD = "world"
DEFAULT_EVERY = 10
"""Control steps between recorded scene frames when ``recording.scene_every`` is null and live is on (50 Hz)."""
HIDDEN_GROUP = 3  # MuJoCo's viewer shows geom groups 0-2 by default; higher groups are hidden here too
LIVE_GEOMETRY_S = 2.0  # a viewer that connects late gets the robot's geometry within this many seconds

_T = {"type": "object", "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}}}
_V3 = {"type": "object", "properties": {k: {"type": "number"} for k in "xyz"}}
_Q = {"type": "object", "properties": {k: {"type": "number"} for k in "xyzw"}}
_RGBA = {"type": "object", "properties": {k: {"type": "number"} for k in "rgba"}}
_POSE = {"type": "object", "properties": {"position": _V3, "orientation": _Q}}
_SOLID = {"type": "object", "properties": {"pose": _POSE, "size": _V3, "color": _RGBA}}
_CYLINDER = {"type": "object", "properties": {"pose": _POSE, "size": _V3, "bottom_scale": {"type": "number"},
                                              "top_scale": {"type": "number"}, "color": _RGBA}}
_LINE = {"type": "object", "properties": {
    "type": {"type": "integer", "description": "0 strip, 1 loop, 2 list"}, "pose": _POSE,
    "thickness": {"type": "number"}, "scale_invariant": {"type": "boolean"},
    "points": {"type": "array", "items": _V3}, "color": _RGBA, "colors": {"type": "array", "items": _RGBA},
    "indices": {"type": "array", "items": {"type": "integer"}}}}
_TRIANGLES = {"type": "object", "properties": {
    "pose": _POSE, "points": {"type": "array", "items": _V3}, "color": _RGBA,
    "colors": {"type": "array", "items": _RGBA}, "indices": {"type": "array", "items": {"type": "integer"}}}}
_ENTITY = {"type": "object", "properties": {
    "timestamp": _T, "frame_id": {"type": "string"}, "id": {"type": "string"}, "lifetime": _T,
    "frame_locked": {"type": "boolean"}, "metadata": {"type": "array"}, "arrows": {"type": "array"},
    "cubes": {"type": "array", "items": _SOLID}, "spheres": {"type": "array", "items": _SOLID},
    "cylinders": {"type": "array", "items": _CYLINDER}, "lines": {"type": "array", "items": _LINE},
    "triangles": {"type": "array", "items": _TRIANGLES}, "texts": {"type": "array"}, "models": {"type": "array"}}}

SCHEMAS = {
    "foxglove.SceneUpdate": {
        "title": "foxglove.SceneUpdate", "description": "entities of a 3-D scene to add or replace",
        "type": "object",
        "properties": {"deletions": {"type": "array"}, "entities": {"type": "array", "items": _ENTITY}}},
    "foxglove.FrameTransforms": {
        "title": "foxglove.FrameTransforms", "description": "poses of coordinate frames (m, unit quaternions)",
        "type": "object", "properties": {"transforms": {"type": "array", "items": {"type": "object", "properties": {
            "timestamp": _T, "parent_frame_id": {"type": "string"}, "child_frame_id": {"type": "string"},
            "translation": _V3, "rotation": _Q}}}}},
    "foxglove.Log": {
        "title": "foxglove.Log", "description": "a log line (level 1 debug, 2 info, 3 warning, 4 error)",
        "type": "object", "properties": {"timestamp": _T, "level": {"type": "integer"}, "message": {"type": "string"},
                                         "name": {"type": "string"}, "file": {"type": "string"},
                                         "line": {"type": "integer"}}},
}
for _name, _schema in SCHEMAS.items():
    register_schema(_name, _schema)

INFO = 2  # foxglove.Log level
GREY, JOINT, PATH = (0.62, 0.64, 0.68, 1.0), (0.95, 0.55, 0.15, 1.0), (0.85, 0.2, 0.2, 0.8)
EE_ACTUAL, EE_DESIRED = (0.1, 0.75, 0.25, 1.0), (0.9, 0.15, 0.15, 1.0)


def stamp(ns: int) -> dict[str, int]:
    sec, nsec = divmod(ns, 1_000_000_000)
    return {"sec": sec, "nsec": nsec}


def _v3(v: Any) -> dict[str, float]:
    return {"x": float(v[0]), "y": float(v[1]), "z": float(v[2])}


def _quat(wxyz: Any) -> dict[str, float]:
    """MuJoCo's (w, x, y, z) as Foxglove's {x, y, z, w}."""
    return {"x": float(wxyz[1]), "y": float(wxyz[2]), "z": float(wxyz[3]), "w": float(wxyz[0])}


def _pose(pos: Any, wxyz: Any = (1.0, 0.0, 0.0, 0.0)) -> dict:
    return {"position": _v3(pos), "orientation": _quat(wxyz)}


def _rgba(c: Any) -> dict[str, float]:
    return {"r": float(c[0]), "g": float(c[1]), "b": float(c[2]), "a": float(c[3])}


def _entity(t_ns: int, frame: str, eid: str, frame_locked: bool = True, **primitives: list) -> dict:
    out = {"timestamp": stamp(t_ns), "frame_id": frame, "id": eid, "lifetime": {"sec": 0, "nsec": 0},
           "frame_locked": frame_locked, "metadata": []}
    for kind in ("arrows", "cubes", "spheres", "cylinders", "lines", "triangles", "texts", "models"):
        out[kind] = primitives.get(kind, [])
    return out


def _rotate(wxyz: np.ndarray, v: np.ndarray) -> np.ndarray:
    out = np.zeros(3)
    mujoco.mju_rotVecQuat(out, v, wxyz)
    return out


def _z_to(d: np.ndarray) -> np.ndarray:
    """The quaternion (w, x, y, z) turning +z onto the direction ``d``."""
    q = np.zeros(4)
    mujoco.mju_quatZ2Vec(q, d)
    return q


def body_frames(model: mujoco.MjModel) -> list[str]:
    """The frame name of every body but the world (its name, or ``body<i>`` when unnamed)."""
    return [model.body(b).name or f"body{b}" for b in range(1, model.nbody)]


def _frame(model: mujoco.MjModel, b: int) -> str:
    return WORLD if b == 0 else (model.body(b).name or f"body{b}")


def _visible(model: mujoco.MjModel) -> np.ndarray:
    return (model.geom_group < HIDDEN_GROUP) & (model.geom_rgba[:, 3] > 0)


def _geom_primitives(model: mujoco.MjModel, g: int) -> dict[str, list]:
    """Foxglove primitives of geom ``g`` in its body's frame (a capsule is a cylinder and two balls)."""
    pos, quat, size = model.geom_pos[g], model.geom_quat[g], model.geom_size[g]
    mat = model.geom_matid[g]
    color = _rgba(model.mat_rgba[mat] if mat >= 0 else model.geom_rgba[g])
    kind = mujoco.mjtGeom(int(model.geom_type[g]))
    G = mujoco.mjtGeom
    if kind in (G.mjGEOM_SPHERE, G.mjGEOM_ELLIPSOID):
        s = 2 * (size if kind == G.mjGEOM_ELLIPSOID else np.full(3, size[0]))
        return {"spheres": [{"pose": _pose(pos, quat), "size": _v3(s), "color": color}]}
    if kind == G.mjGEOM_BOX:
        return {"cubes": [{"pose": _pose(pos, quat), "size": _v3(2 * size), "color": color}]}
    if kind == G.mjGEOM_PLANE:  # size 0: an infinite plane, drawn 4 m wide
        half = [size[0] or 2.0, size[1] or 2.0]
        return {"cubes": [{"pose": _pose(pos, quat), "size": _v3([2 * half[0], 2 * half[1], 0.002]), "color": color}]}
    if kind in (G.mjGEOM_CYLINDER, G.mjGEOM_CAPSULE):
        r, h = size[0], size[1]
        out: dict[str, list] = {"cylinders": [{"pose": _pose(pos, quat), "size": _v3([2 * r, 2 * r, 2 * h]),
                                               "bottom_scale": 1.0, "top_scale": 1.0, "color": color}]}
        if kind == G.mjGEOM_CAPSULE:
            ends = [pos + _rotate(quat, np.array([0.0, 0.0, s * h])) for s in (-1.0, 1.0)]
            out["spheres"] = [{"pose": _pose(e), "size": _v3([2 * r] * 3), "color": color} for e in ends]
        return out
    if kind == G.mjGEOM_MESH:
        m = model.geom_dataid[g]
        va, vn = model.mesh_vertadr[m], model.mesh_vertnum[m]
        fa, fn = model.mesh_faceadr[m], model.mesh_facenum[m]
        points = [_v3(p) for p in model.mesh_vert[va:va + vn]]
        return {"triangles": [{"pose": _pose(pos, quat), "points": points, "color": color, "colors": [],
                               "indices": model.mesh_face[fa:fa + fn].reshape(-1).tolist()}]}
    return {}  # height fields and SDFs are not drawn


def robot_entities(model: mujoco.MjModel, t_ns: int) -> list[dict]:
    """One entity per body with geometry, in the body's own frame (so only the frames move)."""
    visible = _visible(model)
    has_geom = np.zeros(model.nbody, bool)
    has_geom[model.geom_bodyid[visible]] = True
    radius = max(0.01, 0.02 * float(model.stat.extent))
    entities = []
    for b in range(model.nbody):
        prims: dict[str, list] = {}
        for g in np.flatnonzero((model.geom_bodyid == b) & visible):
            for kind, items in _geom_primitives(model, int(g)).items():
                prims.setdefault(kind, []).extend(items)
        if b > 0 and not has_geom[b]:
            prims.setdefault("spheres", []).append(
                {"pose": _pose(np.zeros(3)), "size": _v3([2 * radius] * 3), "color": _rgba(JOINT)})
        for child in np.flatnonzero(model.body_parentid == b):
            d = model.body_pos[child]
            if child == 0 or has_geom[b] or np.linalg.norm(d) < 1e-6:  # the world is its own parent
                continue
            prims.setdefault("cylinders", []).append(
                {"pose": _pose(d / 2, _z_to(d)), "size": _v3([radius, radius, float(np.linalg.norm(d))]),
                 "bottom_scale": 1.0, "top_scale": 1.0, "color": _rgba(GREY)})
        if prims:
            entities.append(_entity(t_ns, _frame(model, b), f"body/{_frame(model, b)}", **prims))
    return entities


def path_entity(t_ns: int, xyz: np.ndarray) -> dict:
    """The desired Cartesian path as a line in the world frame."""
    line = {"type": 0, "pose": _pose(np.zeros(3)), "thickness": 0.004, "scale_invariant": False,
            "points": [_v3(p) for p in xyz], "color": _rgba(PATH), "colors": [], "indices": []}
    return _entity(t_ns, WORLD, "path/desired", frame_locked=False, lines=[line])


def muscles(model: mujoco.MjModel) -> list[tuple[str, int, int]]:
    """(name, tendon, actuator) of every tendon an actuator pulls on."""
    out = []
    for a in range(model.nu):
        if mujoco.mjtTrn(int(model.actuator_trntype[a])) == mujoco.mjtTrn.mjTRN_TENDON:
            t = int(model.actuator_trnid[a, 0])
            out.append((model.actuator(a).name or model.tendon(t).name or f"tendon{t}", t, a))
    return out


def activation_color(a: float) -> dict[str, float]:
    """Blue (0) to red (1)."""
    a = min(max(a, 0.0), 1.0)
    return {"r": 0.15 + 0.8 * a, "g": 0.25 * (1 - a), "b": 0.95 * (1 - a), "a": 1.0}


class SceneWriter:
    """Logs the 3-D scene of ``plant`` into ``rec`` every ``every`` control steps and to ``live``."""

    def __init__(self, plant: Any, rec: Recorder | None, every: int, live: Any = None):
        self.plant, self.rec, self.every, self.live = plant, rec if every > 0 else None, every, live
        self.model: mujoco.MjModel | None = getattr(plant, "model", None)
        self.data: mujoco.MjData | None = getattr(plant, "data", None)
        m = self.model
        self._bodies = list(zip(body_frames(m), range(1, m.nbody))) if m is not None else []
        self._muscles = muscles(m) if m is not None else []
        self._period_s = 1.0 / live.display_hz if live is not None else 0.0
        self._next_live = 0.0
        self._next_geometry = 0.0
        self._robot: list[dict] = []
        if live is not None:  # advertised now, so a viewer already connected subscribes before the first message
            for topic, schema in ((ROBOT, "foxglove.SceneUpdate"), (TRANSFORMS, "foxglove.FrameTransforms"),
                                  (MARKERS, "foxglove.SceneUpdate"), (LOG, "foxglove.Log")):
                live.channel(topic, schema)

    # ---- what the loop calls ------------------------------------------------------------------
    def start_trial(self, t_s: float, trial: int, xyz: np.ndarray | None, record: bool = True) -> None:
        """The robot's geometry and the trial's desired path (again at each trial, so a reader that
        seeks finds them); into the file only when the trial is ``record``-ed (``recording.trials``)."""
        ns = int(round(t_s * 1e9))
        entities = robot_entities(self.model, ns) if self.model is not None else []
        if xyz is not None:
            entities.append(path_entity(ns, xyz))
        self._robot = entities
        self._log(ROBOT, "foxglove.SceneUpdate", t_s, {"deletions": [], "entities": entities}, record, True)

    def step(self, tick: int, t_s: float, ee: np.ndarray | None, ee_des: np.ndarray | None,
             record: bool = True) -> None:
        to_file = record and self.rec is not None and tick % self.every == 0
        to_live = False
        if self.live is not None:
            now = time.perf_counter()
            if now >= self._next_live:
                to_live, self._next_live = True, now + self._period_s
                if now >= self._next_geometry and self._robot:
                    self._next_geometry = now + LIVE_GEOMETRY_S
                    self.live.log(ROBOT, "foxglove.SceneUpdate", t_s, {"deletions": [], "entities": self._robot})
        if not (to_file or to_live):
            return
        ns = int(round(t_s * 1e9))
        self._log(TRANSFORMS, "foxglove.FrameTransforms", t_s, self.transforms(ns), to_file, to_live)
        self._log(MARKERS, "foxglove.SceneUpdate", t_s, self.markers(ns, ee, ee_des), to_file, to_live)
        if to_live:
            self.live.time(t_s)

    def end_trial(self, t_s: float, metrics: Any) -> None:
        self.note(t_s, f"trial {metrics.trial} done: MAE {metrics.mae:.4f} rad")

    def note(self, t_s: float, text: str, level: int = INFO) -> None:
        msg = {"timestamp": stamp(int(round(t_s * 1e9))), "level": level, "message": text, "name": "cerebx",
               "file": "", "line": 0}
        if self.rec is not None:  # the recorder passes it on to a live view
            self.rec.write(LOG, "foxglove.Log", t_s, msg)
        elif self.live is not None:
            self.live.log(LOG, "foxglove.Log", t_s, msg)

    # ---- messages -----------------------------------------------------------------------------
    def transforms(self, ns: int) -> dict:
        ts, pos, quat = stamp(ns), self.data.xpos.tolist(), self.data.xquat.tolist()
        out = []
        for name, b in self._bodies:
            (x, y, z), (qw, qx, qy, qz) = pos[b], quat[b]
            out.append({"timestamp": ts, "parent_frame_id": WORLD, "child_frame_id": name,
                        "translation": {"x": x, "y": y, "z": z}, "rotation": {"x": qx, "y": qy, "z": qz, "w": qw}})
        return {"transforms": out}

    def markers(self, ns: int, ee: np.ndarray | None, ee_des: np.ndarray | None) -> dict:
        size = _v3([0.03] * 3)
        entities = []
        for eid, where, color in (("ee/actual", ee, EE_ACTUAL), ("ee/desired", ee_des, EE_DESIRED)):
            if where is not None:
                entities.append(_entity(ns, WORLD, eid, frame_locked=False, spheres=[
                    {"pose": _pose(where), "size": size, "color": _rgba(color)}]))
        if self._muscles:
            entities.append(_entity(ns, WORLD, "muscles", frame_locked=False, lines=self._muscle_lines()))
        return {"deletions": [], "entities": entities}

    def _muscle_lines(self) -> list[dict]:
        d, m = self.data, self.model
        xpos, obj = d.wrap_xpos.reshape(-1, 3), d.wrap_obj.reshape(-1)
        lines = []
        for _name, t, a in self._muscles:
            adr, n = d.ten_wrapadr[t], d.ten_wrapnum[t]
            pts, idx = xpos[adr:adr + n], []
            for i in range(n - 1):
                if obj[adr + i] != -2 and obj[adr + i + 1] != -2:  # -2: a pulley breaks the path
                    idx += [i, i + 1]
            act = d.act[m.actuator_actadr[a]] if m.actuator_actadr[a] >= 0 else d.ctrl[a]
            lines.append({"type": 2, "pose": _pose(np.zeros(3)), "thickness": 0.006, "scale_invariant": False,
                          "points": [_v3(p) for p in pts], "color": activation_color(float(act)), "colors": [],
                          "indices": idx})
        return lines

    def _log(self, topic: str, schema: str, t_s: float, msg: dict, to_file: bool, to_live: bool) -> None:
        if to_file and self.rec is not None:
            self.rec.write(topic, schema, t_s, msg)
        if to_live and self.live is not None:
            self.live.log(topic, schema, t_s, msg)


def scene_every(cfg: Any) -> int:
    """Control steps between recorded scene frames (0: none) from ``recording.scene_every`` and ``live``."""
    every = cfg.recording.scene_every
    if every is None:
        return DEFAULT_EVERY if cfg.live.enabled else 0
    return every


def scene_writer(cfg: Any, plant: Any, rec: Recorder | None, live: Any) -> SceneWriter | None:
    """The run's scene writer, or None when the scene is neither recorded nor served."""
    every = scene_every(cfg)
    if every == 0 and live is None:
        return None
    return SceneWriter(plant, rec, every, live)
