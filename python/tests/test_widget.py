"""The notebook viewer's event handling, without a browser: a drag turns the camera, the wheel
zooms, and each gives a new frame; the controls change what is drawn."""

import json

import numpy as np

import orbcloud
from conftest import FIXTURES

WATER = FIXTURES / "wavefunctions" / "h2o_ccpvtz.molden"
BEND = sorted((FIXTURES / "scans" / "water_bend").glob("*.molden.gz"))


def camera(viewer):
    return json.loads(viewer.canvas.scene.camera)


def test_drag_turns_and_wheel_zooms():
    viewer = orbcloud.widget(orbcloud.load(WATER), size=(120, 90), lavapipe=True)
    canvas = viewer.canvas
    first = np.asarray(canvas.get_frame()).copy()
    before = camera(viewer)
    canvas.handle_event({"event_type": "pointer_down", "x": 60, "y": 45, "button": 1, "buttons": [1], "modifiers": []})
    canvas.handle_event({"event_type": "pointer_move", "x": 90, "y": 55, "button": 0, "buttons": [1], "modifiers": []})
    canvas.handle_event({"event_type": "pointer_up", "x": 90, "y": 55, "button": 1, "buttons": [], "modifiers": []})
    turned = camera(viewer)
    assert turned["yaw"] != before["yaw"] and turned["pitch"] != before["pitch"]
    second = np.asarray(canvas.get_frame()).copy()
    assert second.shape == (90, 120, 4)
    assert np.abs(second.astype(int) - first).sum() > 0, "turning gave the same frame"
    canvas.handle_event({"event_type": "wheel", "x": 60, "y": 45, "dx": 0, "dy": 120, "modifiers": []})
    assert camera(viewer)["distance"] > turned["distance"]
    third = np.asarray(canvas.get_frame()).copy()
    assert np.abs(third.astype(int) - second).sum() > 0


def test_controls_redraw_and_keep_the_camera():
    viewer = orbcloud.widget(orbcloud.load(WATER), size=(96, 72), lavapipe=True)
    canvas = viewer.canvas
    canvas.scene.orbit(0.5, 0.2)
    turned = camera(viewer)
    homo = np.asarray(canvas.get_frame()).copy()
    viewer.orbital.value = viewer.orbital.options[-1][1] if isinstance(viewer.orbital.options[-1], tuple) else viewer.orbital.options[-1]
    assert camera(viewer) == turned
    other = np.asarray(canvas.get_frame()).copy()
    assert np.abs(other.astype(int) - homo).sum() > 0
    viewer.style.value = "cloud"
    cloud = np.asarray(canvas.get_frame()).copy()
    assert np.abs(cloud.astype(int) - other).sum() > 0
    viewer.style.value = "isosurfaces"
    viewer.iso.value = viewer.iso.value * 2
    assert "--iso" in canvas.words


def test_scan_slider_moves_along_the_frames():
    docs = [orbcloud.load(p) for p in BEND[:3]]
    viewer = orbcloud.widget(docs, size=(96, 72), lavapipe=True)
    assert viewer.frame is not None and viewer.frame.max == 2
    first = np.asarray(viewer.canvas.get_frame()).copy()
    viewer.frame.value = 2
    last = np.asarray(viewer.canvas.get_frame()).copy()
    assert np.abs(last.astype(int) - first).sum() > 0


def test_events_from_another_thread():
    """ipykernel may deliver a widget's messages on a thread of its own."""
    import threading

    viewer = orbcloud.widget(orbcloud.load(WATER), size=(64, 48), lavapipe=True)
    before = camera(viewer)
    errors = []

    def drag():
        try:
            viewer.canvas.handle_event({"event_type": "pointer_down", "x": 10, "y": 10, "button": 1, "buttons": [1], "modifiers": []})
            viewer.canvas.handle_event({"event_type": "pointer_move", "x": 30, "y": 12, "button": 0, "buttons": [1], "modifiers": []})
            viewer.canvas.get_frame()
        except Exception as e:  # reported below, on the test's thread
            errors.append(e)

    thread = threading.Thread(target=drag)
    thread.start()
    thread.join()
    assert not errors, errors
    assert camera(viewer)["yaw"] != before["yaw"]


def test_scan_manifest_gives_the_slider():
    scan = orbcloud.load_scan(FIXTURES / "scans" / "water_path" / "water_path.scan.toml")
    assert scan.coordinate == "path" and scan.values == [0, 1, 2, 3] and len(scan.frames) == 4
    viewer = orbcloud.widget(scan, size=(64, 48), lavapipe=True)
    assert viewer.frame.max == 3 and viewer.frame_label.value == "path = 0.00"
    viewer.frame.value = 3
    assert viewer.frame_label.value == "path = 3.00"


def test_natural_transition_orbitals_in_the_menu():
    from pyscf import gto, scf, tdscf

    mol = gto.M(atom="O 0 0 0.117; H 0 0.757 -0.467; H 0 -0.757 -0.467", basis="sto-3g", verbose=0)
    nto = orbcloud.from_pyscf(tdscf.TDA(scf.RHF(mol).run()).run(nstates=1)).nto(1)
    viewer = orbcloud.widget(nto, size=(96, 72), lavapipe=True)
    labels = [label for label, _ in viewer.orbital.options]
    assert labels[0].startswith("hole 1 (weight") and labels[1].startswith("particle 1")
    assert viewer.orbital.value == "1"  # hole 1 first
    hole = np.asarray(viewer.canvas.get_frame()).copy()
    viewer.orbital.value = viewer.orbital.options[1][1]
    assert "--orbital" in viewer.canvas.words and "2" in viewer.canvas.words
    assert np.abs(np.asarray(viewer.canvas.get_frame()).astype(int) - hole).sum() > 0
