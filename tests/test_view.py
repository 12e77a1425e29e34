"""flipkit view: the plan's motion on one clock, the self-contained page (its animation, no
URL fetched), the command line (written page, served page, refused plans)."""

import base64
from dataclasses import replace
import json
import re
import subprocess
import sys
import urllib.request
from html.parser import HTMLParser

import numpy as np
import pytest
import umsgpack
import zmq

from flipkit.config.task import TILT_MIN_DEG
from flipkit.cli import main
from flipkit.cli import view as cli_view
from flipkit.cli.commands import view as view_command
from flipkit.errors import ConfigError, InvalidChoiceError, VerificationError
from flipkit.viz import server, viewer
from flipkit.viz.motion import plan_motion

COMMAND = re.compile(r'fetch\("data:application/octet-binary;base64,([A-Za-z0-9+/=]+)"\)')


@pytest.fixture(scope="module")
def page(flip_plan):
    return viewer.static_html(flip_plan)


def commands(page: str) -> list[dict]:
    """The drawing commands inlined in the page (msgpack, base64)."""
    return [umsgpack.unpackb(base64.b64decode(c)) for c in COMMAND.findall(page)]


class Tags(HTMLParser):
    """Every tag of a page with its attributes."""

    def __init__(self):
        super().__init__()
        self.tags = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))


def test_the_motion_follows_the_plan(flip_plan):
    m = plan_motion(flip_plan, fps=50)
    ends = np.cumsum([s.T for s in flip_plan.segments])
    flip = flip_plan.segment("flip")
    assert m.t[0] == 0 and m.t[-1] >= ends[-1] and np.allclose(np.diff(m.t), 0.02)
    np.testing.assert_allclose(m.q[0], flip_plan.segments[0].q[0], atol=1e-12)
    h = flip_plan.burger["thickness"]
    np.testing.assert_allclose(m.burger[0][:3, 3], flip_plan.burger["location"] + [0, 0, h / 2])
    # riding the blade in the pickup: the blade's pose, half a thickness up, at burger_on_blade
    k = int(np.searchsorted(m.t, ends[1] + 0.1))
    robot = flip_plan.robot_for(flip_plan.segments[0])
    blade = robot.placement(m.q[k]).homogeneous
    local = np.linalg.solve(blade, m.burger[k])
    np.testing.assert_allclose(local[:3, 3], [*flip.landing["burger_on_blade"], h / 2], atol=1e-12)
    np.testing.assert_allclose(local[:3, :3], np.eye(3), atol=1e-12)
    # landed (the end): on the recorded point, upside down as recorded
    np.testing.assert_allclose(m.burger[-1][:3, 3], flip.landing["point"], atol=1e-6)
    tilt = np.degrees(np.arccos(m.burger[-1][2, 2]))
    assert tilt == pytest.approx(flip.landing["tilt_deg"], abs=1e-3) and tilt >= TILT_MIN_DEG - 1e-3
    assert m.landing.radius == flip.landing["r_land"] and len(m.landing.arc) > 2
    np.testing.assert_allclose(m.landing.arc[-1], flip.landing["point"], atol=1e-6)
    with pytest.raises(ConfigError, match="fps must be"):
        plan_motion(flip_plan, fps=0.0)


def test_the_page_holds_the_animation_and_fetches_no_url(page, flip_plan):
    cmds = commands(page)
    objects = {c["path"] for c in cmds if c["type"] == "set_object"}
    for part in ("cell/grill", "cell/table", "burger/shape", "spatula/blade/shape",
                 "spatula/handle/shape", "landing/spot/shape", "landing/arc"):
        assert f"/meshcat/flipkit/{part}" in objects, part
    arm = {p for p in objects if p.startswith("/meshcat/flipkit/arm/visuals/")}
    assert len(arm) == 8  # the URDF's collision meshes of 7 links and its 1 cm ee_link box
    (anim,) = [c for c in cmds if c["type"] == "set_animation"]
    paths = {a["path"] for a in anim["animations"]}
    assert {"/meshcat/flipkit/burger", "/meshcat/flipkit/spatula/blade"} <= paths
    assert len(paths) == 8 + 3 and anim["options"]["play"] is True
    total = sum(s.T for s in flip_plan.segments)
    for a in anim["animations"]:
        clip = a["clip"]
        times = [k["time"] for k in clip["tracks"][0]["keys"]]
        assert clip["fps"] == 50 and times[-1] / clip["fps"] >= total
    # self-contained: no tag loads anything from a URL, no command fetches one
    tags = Tags()
    tags.feed(page)
    assert [t for t, a in tags.tags if t == "script" and "src" in a] == []
    linked = [a.get("src") or a.get("href") for _, a in tags.tags if a.get("src") or a.get("href")]
    assert linked == []
    assert not re.search(r"""fetch\(\s*["'](?!data:)""", page)
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:)?//""", page)


def test_options_are_checked_and_unverified_plans_refused(flip_plan):
    with pytest.raises(InvalidChoiceError, match="arm meshes"):
        viewer.static_html(flip_plan, meshes="fancy")
    failed = replace(flip_plan, status="failed")
    with pytest.raises(VerificationError, match="needs a solved"):
        viewer.view_plan(failed, vis=object())  # refused before anything is drawn
    assert cli_view.MESHES == tuple(viewer.MESHES)


def test_cli_writes_the_page(flip_plan_file, tmp_path, capsys):
    out = tmp_path / "view.html"
    assert main(["view", str(flip_plan_file), "--html", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    assert out.read_text().lstrip().startswith("<!DOCTYPE html>")
    assert main(["view", str(flip_plan_file), "--html", str(tmp_path / "view.png")]) == 2
    assert "--html" in capsys.readouterr().err


def test_cli_refuses_a_tampered_plan(flip_plan_file, tmp_path, capsys):
    """A joint angle moved by 0.01 rad: verify fails it, so view refuses it in one line
    (exit 2) and writes no page."""
    doc = json.loads(flip_plan_file.read_text())
    doc["segments"][1]["q"][5][2] += 0.01
    path = tmp_path / "tampered.json"
    path.write_text(json.dumps(doc))
    out = tmp_path / "view.html"
    assert main(["view", str(path), "--html", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith("flipkit: error:") and "refused" in err
    assert not out.exists()
    assert main(["view", str(path), "--no-browser"]) == 2  # no server either


def test_cli_serves_the_page_until_stopped(flip_plan_file, monkeypatch, capsys):
    seen = {}

    def fetch(vis):  # instead of waiting for Ctrl-C: load the served page once
        with urllib.request.urlopen(vis.url(), timeout=30) as reply:
            seen["status"], seen["body"] = reply.status, reply.read().decode()
        seen["proc"] = vis.window.server_proc

    monkeypatch.setattr(view_command, "wait", fetch)
    monkeypatch.setattr(view_command.webbrowser, "open", lambda *a, **k: seen.update(opened=1))
    assert main(["view", str(flip_plan_file), "--no-browser"]) == 0
    url = re.search(r"http://127\.0\.0\.1:\d+/static/", capsys.readouterr().out)
    assert url and seen["status"] == 200 and "MeshCat" in seen["body"]
    assert "opened" not in seen and seen["proc"].poll() is not None  # the server is stopped


def test_a_stopped_server_is_an_error_not_a_hang(flip_plan):
    import socket
    from urllib.parse import urlparse

    vis = server.open_visualizer()
    vis.window.zmq_socket.setsockopt(zmq.RCVTIMEO, 500)
    server.close_visualizer(vis)
    # Hold the stopped server's port: ZMQ reconnects by itself, and a MeshCat server that
    # another test worker starts would otherwise take the freed port and answer.
    url = urlparse(vis.window.zmq_url)
    with socket.socket() as holder:
        holder.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        holder.bind((url.hostname, url.port))
        holder.listen()
        with pytest.raises(server.ViewerError, match="did not answer"):
            server.page(vis)


def test_inline_puts_the_page_in_an_iframe(flip_plan, monkeypatch):
    monkeypatch.setattr(viewer, "static_html", lambda plan, **o: '<p class="a">&</p>')
    cell = viewer.inline(flip_plan, height=300).data
    assert 'srcdoc="&lt;p class=&quot;a&quot;&gt;&amp;&lt;/p&gt;"' in cell and "300px" in cell


def test_a_malformed_plan_is_refused_before_meshcat_is_imported(tmp_path):
    """In a fresh interpreter: `flipkit view` parses and refuses a malformed file without
    importing MeshCat or pinocchio (``flipkit --help`` stays as fast)."""
    bad = tmp_path / "bad.json"
    bad.write_text("{oops")
    script = ("import sys; from flipkit.cli import main; rc = main(sys.argv[1:]); "
              "print(rc, 'meshcat' in sys.modules, 'pinocchio' in sys.modules)")
    run = subprocess.run([sys.executable, "-c", script, "view", str(bad), "--html",
                          str(tmp_path / "v.html")], capture_output=True, text=True, timeout=60)
    assert run.stdout.split() == ["2", "False", "False"], run.stdout + run.stderr
    assert not (tmp_path / "v.html").exists()
