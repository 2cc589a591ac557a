#!/usr/bin/python3
"""quiver-view under Xvfb, as a user would run it: bounded runs with a scripted mouse write
screenshots, which must show the model, show it moved by the drag, show the panel, and show a mode;
bad input is refused with a clear message and no screenshot."""
import os
import shutil
import subprocess
import tempfile
import unittest

import numpy as np

VIEW = os.environ["QUIVER_VIEW"]
MODEL = os.environ["QUIVER_MODEL"]
FREE_MODEL = os.environ["QUIVER_FREE_MODEL"]
XVFB_RUN = shutil.which("xvfb-run")
SIZE = "640,400"

# The suite's beam (0.6 m, fixed at x = min) seen from the default camera: its free end is near the
# lower left of the window. Press there, drag down over half a second, hold, let go, and look while
# it still rings.
DRAG = """# frame action x y
10 press 0.36 0.68
40 move 0.36 0.95
70 release
"""


@unittest.skipUnless(XVFB_RUN, "SKIPPED: xvfb-run not found (Debian package xvfb): cannot open a window here")
class QuiverView(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.script = os.path.join(cls.tmp.name, "drag.txt")
        with open(cls.script, "w") as f:
            f.write(DRAG)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def view(self, *args, display=True, model=MODEL):
        command = [VIEW, model, *([] if "--size" in args else ["--size", SIZE]), *map(str, args)]
        if display:
            command = [XVFB_RUN, "-a", "-s", "-screen 0 1280x1024x24", *command]
        return subprocess.run(command, capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)

    def shot(self, name, *args, frames=90):
        path = os.path.join(self.tmp.name, name)
        p = self.view("--frames", frames, "--screenshot", path, *args)
        self.assertEqual(p.returncode, 0, p.stderr)
        import matplotlib.image
        return matplotlib.image.imread(path)[:, :, :3], p.stdout

    @staticmethod
    def model_pixels(image):
        background = image[-1, -1]  # the bottom-right corner: neither panel nor model
        return np.abs(image - background).max(axis=2) > 0.05

    def test_drag_moves_the_model_and_it_rings_after_release(self):
        rest, out = self.shot("rest.png", "--no-panel")
        self.assertEqual(rest.shape, (400, 640, 3))
        covered = self.model_pixels(rest).mean()
        self.assertGreater(covered, 0.02)  # not blank
        self.assertLess(covered, 0.9)  # the camera frames it
        self.assertIn("0 grabs", out)
        dragged, out = self.shot("dragged.png", "--no-panel", "--drag-script", self.script)
        self.assertIn("1 grabs", out)
        self.assertIn("0 resets", out)
        changed = (np.abs(dragged - rest).max(axis=2) > 0.1).mean()
        self.assertGreater(changed, 0.01, "the screenshot after the drag should differ from the rest pose")
        # While held (frame 60), the model reaches lower than at rest: the script drags down.
        held, _ = self.shot("held.png", "--no-panel", "--drag-script", self.script, frames=60)
        lowest = lambda image: np.nonzero(self.model_pixels(image).any(axis=1))[0].max()
        self.assertGreater(lowest(held), lowest(rest) + 10)

    def test_panel_is_drawn(self):
        bare, _ = self.shot("bare.png", "--no-panel")
        panel, _ = self.shot("panel.png")
        corner = (slice(20, 200), slice(20, 300))  # where the panel opens
        self.assertGreater(bare[corner].mean(), 0.8)  # light background
        self.assertLess(panel[corner].mean(), 0.5)  # the dark panel
        self.assertGreater(len(np.unique(panel[corner].reshape(-1, 3), axis=0)), 10)  # text and widgets, not a flat box

    def test_a_scripted_click_on_the_panel_turns_gravity_on(self):
        # The panel opens at the top left with ImGui 1.86's default font: the gravity checkbox sits at
        # pixel (27, 336) of a 1280 x 800 window. The click is the panel's: no grab.
        click = os.path.join(self.tmp.name, "click.txt")
        with open(click, "w") as f:
            f.write("10 press 0.021 0.42\n12 release\n")
        plain, _ = self.shot("no_click.png", "--size", "1280,800")
        fallen, out = self.shot("gravity.png", "--size", "1280,800", "--drag-script", click)
        self.assertIn("0 grabs", out)
        right = (slice(None), slice(450, None))  # clear of the panel
        lowest = lambda image: np.nonzero(self.model_pixels(image[right]).any(axis=1))[0].max()
        self.assertGreater(lowest(fallen), lowest(plain) + 20, "the beam should sag once gravity is on")

    def test_mode_browser_shows_a_mode(self):
        rest, _ = self.shot("rest_for_mode.png", "--no-panel")
        # 23 frames of 1/60 s: about a quarter of the browser's 1.5 s oscillation, near full amplitude.
        path = os.path.join(self.tmp.name, "mode.png")
        p = self.view("--frames", 23, "--screenshot", path, "--no-panel", "--show-mode", "linear:0")
        self.assertEqual(p.returncode, 0, p.stderr)
        import matplotlib.image
        mode = matplotlib.image.imread(path)[:, :, :3]
        self.assertGreater((np.abs(mode - rest).max(axis=2) > 0.1).mean(), 0.01)

    @staticmethod
    def bodies(out):
        """The centres and velocities a bounded free-flight run prints at its end."""
        rows = [line.split() for line in out.splitlines() if line.startswith("quiver-view: body ")]
        return [(np.array(list(map(float, r[4:7]))), np.array(list(map(float, r[9:12])))) for r in rows]

    def test_a_free_object_drops_is_lifted_and_thrown(self):
        # Dropped from one height onto the default ground: at rest on it after a second.
        landed_png = os.path.join(self.tmp.name, "landed.png")
        p = self.view("--free", "--frames", 60, "--screenshot", landed_png, "--no-panel", model=FREE_MODEL)
        self.assertEqual(p.returncode, 0, p.stderr)
        (centre, velocity), = self.bodies(p.stdout)
        self.assertAlmostEqual(centre[2], 0.05, delta=0.003)  # its half height: resting on its underside
        self.assertLess(np.linalg.norm(velocity), 0.01)
        # Find it on the screen, press on it, pull the cursor up, swing it sideways and let go.
        import matplotlib.image
        image = matplotlib.image.imread(landed_png)[:, :, :3]
        blue = image[:, :, 2] - image[:, :, 0] > 0.2
        rows, columns = np.nonzero(blue)
        x, y = columns.mean() / image.shape[1], rows.mean() / image.shape[0]
        script = os.path.join(self.tmp.name, "throw.txt")
        with open(script, "w") as f:
            f.write(f"61 press {x:.4f} {y:.4f}\n100 move {x:.4f} {y - 0.25:.4f}\n110 move {x + 0.25:.4f} {y - 0.25:.4f}\n"
                    f"111 release\n")
        p = self.view("--free", "--frames", 100, "--no-panel", "--drag-script", script, model=FREE_MODEL)
        self.assertIn("1 grabs", p.stdout)
        (held, _), = self.bodies(p.stdout)
        self.assertGreater(held[2], 0.1, "lifted off the ground")
        p = self.view("--free", "--frames", 112, "--no-panel", "--drag-script", script, model=FREE_MODEL)
        (_, thrown), = self.bodies(p.stdout)
        self.assertGreater(np.linalg.norm(thrown[:2]), 0.3, "let go while moving: thrown")
        p = self.view("--free", "--frames", 240, "--no-panel", "--drag-script", script, model=FREE_MODEL)
        (end, _), = self.bodies(p.stdout)
        print(f"landed at {centre}, held at {held}, thrown at {thrown} m/s, came down at {end}")
        self.assertGreater(np.linalg.norm(end[:2] - centre[:2]), 0.1, "it flew somewhere else")
        self.assertIn("0 resets", p.stdout)
        # A pile of 8 is drawn and rests (kept awake, so that it rests by itself).
        p = self.view("--free", "--pile", 8, "--sleep-speed", 0, "--frames", 150, "--no-panel", model=FREE_MODEL)
        piled = self.bodies(p.stdout)
        self.assertEqual(len(piled), 8)
        self.assertLess(max(np.linalg.norm(v) for _, v in piled), 0.01)
        # With soft contacts, dropped the same way: at rest on its underside as well.
        p = self.view("--free", "--soft-contacts", "--frames", 60, "--no-panel", model=FREE_MODEL)
        (soft, velocity), = self.bodies(p.stdout)
        self.assertAlmostEqual(soft[2], 0.05, delta=0.003)
        self.assertLess(np.linalg.norm(velocity), 0.01)
        # A fast spin's steps are cut into substeps unless --max-substeps 1 says otherwise: the
        # same throw ends elsewhere.
        spin = ("--free", "--angular-velocity", "0,0,200", "--frames", 20, "--no-panel")
        (cut, _), = self.bodies(self.view(*spin, model=FREE_MODEL).stdout)
        (whole, _), = self.bodies(self.view(*spin, "--max-substeps", 1, model=FREE_MODEL).stdout)
        self.assertGreater(np.linalg.norm(cut - whole), 1e-9)

    def test_bad_input_is_refused_without_a_screenshot(self):
        bad = os.path.join(self.tmp.name, "bad.txt")
        with open(bad, "w") as f:
            f.write("10 press 0.5 0.5\n5 release\n")
        shot = os.path.join(self.tmp.name, "never.png")
        for args, message in ((["--drag-script", bad], "bad.txt:2: frame 5 comes before"),
                              (["--drag-script", os.path.join(self.tmp.name, "none.txt")], "none.txt"),
                              (["--show-mode", "linear:99"], "--show-mode linear:99"),
                              (["--show-mode", "sideways:1"], "expected linear:N or basis:N"),
                              (["--pile", 3], "need --free"), (["--free"], "was baked with fixed vertices"),
                              (["--soft-contacts"], "--soft-contacts needs --free"),
                              (["--max-substeps", 4], "--max-substeps needs --free")):
            with self.subTest(args=args):
                p = self.view("--frames", 5, "--screenshot", shot, *args)
                self.assertEqual(p.returncode, 1, p.stderr)
                self.assertIn(message, p.stderr)
                self.assertFalse(os.path.exists(shot))
        p = self.view("--screenshot", shot)
        self.assertIn("--screenshot needs --frames", p.stderr)
        p = subprocess.run([VIEW, os.path.join(self.tmp.name, "none.qvr"), "--frames", "1"], capture_output=True, text=True)
        self.assertEqual(p.returncode, 1)
        self.assertIn("none.qvr: cannot open", p.stderr)

    def test_without_a_display_it_says_what_to_do(self):
        env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
        p = subprocess.run([VIEW, MODEL, "--frames", "1"], capture_output=True, text=True, env=env, timeout=60)
        self.assertEqual(p.returncode, 1)
        self.assertIn("xvfb-run", p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
