"""The notebook viewer: frames drawn offscreen by orbcloud's renderer and sent to the browser
as a remote frame buffer (jupyter_rfb); pointer and wheel events come back and turn or zoom the
camera. Controls (ipywidgets) pick the orbital, the isovalue, cloud or isosurfaces, and a
scan's frame."""

from __future__ import annotations

import math
from typing import Sequence

import ipywidgets as widgets
from jupyter_rfb import RemoteFrameBuffer

from . import Document, Scan, _native, _resolved, _words, load

# Radians per pixel dragged, and the wheel's zoom per unit of scroll: the desktop viewer's.
DRAG_ROTATE = 0.008
WHEEL_ZOOM = 0.002

STYLES = ("isosurfaces", "cloud", "both")


class Canvas(RemoteFrameBuffer):
    """One document's scene, drawn as ``orbcloud render`` draws it with ``options``, seen by a
    camera the mouse turns (drag) and zooms (wheel)."""

    def __init__(self, doc: Document, size=(600, 450), **options):
        width, height = (int(v) for v in size)
        super().__init__(css_width=f"{width}px", css_height=f"{height}px", resizable=False)
        self.size = (width, height)
        self._drag = None
        self.scene = None
        self.show(doc, **options)

    @property
    def words(self) -> list[str]:
        """The options of ``orbcloud render`` the scene is drawn with."""
        return _words({"size": self.size, **_resolved(self.doc, self.options)[1]})

    def show(self, doc: Document | None = None, **options) -> None:
        """Shows another document or other options (merged into the current ones; ``None``
        removes one), keeping the camera."""
        if doc is not None:
            self.doc = doc
        current = dict(getattr(self, "options", {}))
        current.update(options)
        self.options = {k: v for k, v in current.items() if v is not None}
        camera = self.scene.camera if self.scene is not None else None
        self.scene = _native.Scene(_resolved(self.doc, self.options)[0]._native, self.words)
        if camera is not None:
            self.scene.camera = camera
        self.request_draw()

    def handle_event(self, event: dict) -> None:
        kind = event.get("event_type") or event.get("type")
        if kind == "pointer_down":
            self._drag = (event["x"], event["y"])
        elif kind == "pointer_move" and self._drag is not None:
            x, y = event["x"], event["y"]
            dx, dy = x - self._drag[0], y - self._drag[1]
            self._drag = (x, y)
            self.scene.orbit(-dx * DRAG_ROTATE, dy * DRAG_ROTATE)
            self.request_draw()
        elif kind == "pointer_up":
            self._drag = None
        elif kind == "wheel":
            self.scene.zoom(math.exp(event.get("dy", 0.0) * WHEEL_ZOOM))
            self.request_draw()
        elif kind == "double_click":
            self.scene.reset()
            self.request_draw()

    def get_frame(self):
        return self.scene.draw()


# Pairs of natural transition orbitals the widget lists.
NTO_PAIRS = 4


def _orbital_choices(doc: Document) -> list[tuple[str, str]]:
    """(label, ``--orbital``/``--density`` word) for the orbitals around the frontier and the
    density; for natural transition orbitals (:meth:`Document.nto`), the main pairs."""
    choices = []
    orbitals = [o for o in doc.orbitals if o.spin == "alpha"]
    if orbitals and doc.weights is not None:
        for i, o in enumerate(orbitals[: 2 * NTO_PAIRS]):
            choices.append((f"{o.label} (weight {o.occupation:.3f})", str(i + 1)))
        return choices
    if orbitals:
        homo = doc.orbital_index("homo")
        for i in range(max(0, homo - 3), min(len(orbitals), homo + 5)):
            name = "HOMO" if i == homo else ("LUMO" if i == homo + 1 else (f"HOMO−{homo - i}" if i < homo else f"LUMO+{i - homo - 1}"))
            energy = orbitals[i].energy
            label = f"{name} (MO {i}, {energy:.4f} Eh)" if energy == energy else f"{name} (MO {i})"
            choices.append((label, str(i + 1)))
        choices.append(("density", "density"))
    return choices


class Viewer(widgets.VBox):
    """:class:`Canvas` with its controls; a list of documents (a scan's frames) adds a slider."""

    def __init__(self, doc_or_docs, size=(600, 450), orbital: str | int | None = None, iso: float = 0.05, style: str = "isosurfaces", **options):
        self.labels = None
        if isinstance(doc_or_docs, Scan):
            docs: Sequence[Document] = doc_or_docs.frames
            self.labels = [f"{doc_or_docs.coordinate} = {label}" for label in doc_or_docs.labels]
        elif isinstance(doc_or_docs, (list, tuple)):
            docs = [d if isinstance(d, Document) else load(d) for d in doc_or_docs]
        else:
            docs = [doc_or_docs if isinstance(doc_or_docs, Document) else load(doc_or_docs)]
        if not docs:
            raise ValueError("nothing to show")
        if style not in STYLES:
            raise ValueError(f"style must be one of {STYLES}")
        self.docs = docs
        doc = docs[0]
        choices = _orbital_choices(doc)
        start = None
        if orbital is None:
            orbital = "hole 1" if doc.weights is not None else "homo"
        if choices:
            index = orbital if isinstance(orbital, int) else doc.orbital_index(orbital)
            start = str(index + 1)
            if start not in [word for _, word in choices]:
                choices.insert(0, (f"MO {index}", start))
        self.orbital = widgets.Dropdown(options=choices, value=start, description="orbital", disabled=not choices)
        self.iso = widgets.FloatLogSlider(value=iso, base=10, min=-3, max=0, step=0.05, description="isovalue", readout_format=".3f")
        self.style = widgets.ToggleButtons(options=list(STYLES), value=style, description="show")
        self.frame = None
        controls = [self.orbital, self.iso, self.style]
        if len(docs) > 1:
            self.frame = widgets.IntSlider(value=0, min=0, max=len(docs) - 1, description="frame", continuous_update=False)
            self.frame_label = widgets.Label(self._frame_name(0))
            controls.append(widgets.HBox([self.frame, self.frame_label]))
        self.canvas = Canvas(doc, size=size, **self._options(), **options)
        for control in (self.orbital, self.iso, self.style):
            control.observe(self._changed, names="value")
        if self.frame is not None:
            self.frame.observe(self._frame_changed, names="value")
        super().__init__(children=[widgets.HBox(controls[:2]), widgets.HBox(controls[2:]), self.canvas])

    def _frame_name(self, i: int) -> str:
        return self.labels[i] if self.labels else self.docs[i].source

    def _options(self) -> dict:
        quantity = self.orbital.value
        style = self.style.value
        return {
            "orbital": None if quantity in (None, "density") else quantity,
            "density": quantity == "density",
            "iso": None if style == "cloud" else float(self.iso.value),
            "no_volume": style == "isosurfaces",
        }

    def _changed(self, _change=None) -> None:
        self.canvas.show(**self._options())

    def _frame_changed(self, change) -> None:
        doc = self.docs[change["new"]]
        self.frame_label.value = self._frame_name(change["new"])
        self.canvas.show(doc, **self._options())
