// The live page: frames of a chain simulated on the server arrive over a WebSocket and
// are drawn (draw.js); the controls and a drag of the pivot go back as JSON controls
// (pendulum-cli/src/view/live/session.rs). `#selftest` drags the pivot by script and
// reports, on the page and to the server, whether the chain followed.
"use strict";
(function () {
  const $ = (id) => document.getElementById(id);
  const canvas = $("chain");
  // `#drag`: the pivot dragged by script after half a second; `#selftest`: the same, with
  // a report; `#hold=S` (for a headless browser's screenshot): a request the server holds
  // open S seconds. They combine: `#selftest&hold=4`.
  const options = new URLSearchParams(location.hash.slice(1));
  if (options.has("hold")) fetch(`/hold/${Number(options.get("hold"))}`);
  const socket = new WebSocket(`ws://${location.host}/socket`);
  const send = (control) => { if (socket.readyState === 1) socket.send(JSON.stringify(control)); };
  const view = { corotating: false, trail: true };
  let frame = null, camera = null, count = 0;
  const drags = { grabbed: 0, sent: 0 };
  const tips = [];

  // Point k (0: the pivot) of frame f, m; co-rotating: turned back by the pivot's
  // azimuth about the vertical through the centre it circles.
  function point(f, k) {
    const p = [f.points[3 * k], f.points[3 * k + 1], f.points[3 * k + 2]];
    return view.corotating ? turned(p, f.centre, f.phase) : p;
  }
  function turned(p, c, phase) {
    const s = Math.sin(-phase), o = Math.cos(-phase), x = p[0] - c[0], y = p[1] - c[1];
    return [c[0] + o * x - s * y, c[1] + s * x + o * y, p[2]];
  }
  const points = (f) => Array.from({ length: f.points.length / 3 }, (_, k) => point(f, k));

  function draw() {
    if (!frame) return;
    const f = frame, reach = f.chain[2];
    camera.clear();
    camera.axis(f.centre[0], f.centre[1], f.centre[2] + 0.1 * reach, f.centre[2] - 1.1 * reach);
    camera.scaleBar();
    if (view.trail) camera.trail(tips.map(([p, c, phase]) => view.corotating ? turned(p, c, phase) : p));
    camera.chain(points(f));
    camera.label(`t = ${f.t.toFixed(2)} s${view.corotating ? " (co-rotating)" : ""}`);
  }

  // A drag that starts on the pivot moves the centre it circles with the pointer.
  function grab(x, y) {
    const p = camera.project(point(frame, 0));
    if (Math.hypot(p[0] - x, p[1] - y) > 25) return null;
    const start = frame.target.slice();
    drags.grabbed++;
    return (dx, dy) => {
      const d = camera.unproject(dx, dy);
      drags.sent++;
      send({ target: start.map((v, k) => v + d[k]) });
    };
  }

  function controls(f) {
    const reach = f.chain[2];
    $("radius").max = String(reach / 2);
    $("radius").step = String(reach / 1000);
    $("omega").value = String(f.aims[1]);
    $("radius").value = String(f.aims[0]);
    $("damping").value = String(Math.log10(Math.max(f.damping, 1e-7)));
    const label = () => {
      $("omega-value").textContent = `${Number($("omega").value).toFixed(1)} rad/s`;
      $("radius-value").textContent = `${Number($("radius").value).toPrecision(3)} m`;
      const d = Number($("damping").value);
      $("damping-value").textContent = d <= -7 ? "0" : `${Math.pow(10, d).toExponential(1)} N·m·s`;
    };
    label();
    // The damping as it is, not as the slider's tenths of a decade round it.
    $("damping-value").textContent = `${f.damping.toExponential(1)} N·m·s`;
    $("omega").addEventListener("input", () => { label(); send({ omega: Number($("omega").value) }); });
    $("radius").addEventListener("input", () => { label(); send({ radius: Number($("radius").value) }); });
    $("damping").addEventListener("input", () => {
      label();
      const d = Number($("damping").value);
      send({ damping: d <= -7 ? 0 : Math.pow(10, d) });
    });
    $("centre").addEventListener("click", () => send({ target: [0, 0, 0] }));
    $("restart").addEventListener("click", () => { tips.length = 0; send("restart"); });
    $("corotating").addEventListener("change", (e) => { view.corotating = e.target.checked; draw(); });
    $("trail").addEventListener("change", (e) => { view.trail = e.target.checked; draw(); });
  }

  socket.onmessage = (message) => {
    const f = JSON.parse(message.data);
    if (f.error) $("error").textContent = f.error;
    if (f.t === undefined) return;
    if (!camera) {
      const reach = f.chain[2];
      frame = f;
      camera = chainView(canvas, [0, 0, -0.45 * reach], 1.3 * reach, true);
      camera.orbit(draw, grab);
      controls(f);
    }
    frame = f; count++;
    const n = f.points.length / 3 - 1;
    tips.push([[f.points[3 * n], f.points[3 * n + 1], f.points[3 * n + 2]], f.centre, f.phase]);
    if (tips.length > 240) tips.shift();
    draw();
    $("status").textContent =
      `${f.chain[0]} links, M = ${f.chain[1].toPrecision(4)} kg, L = ${f.chain[2].toPrecision(4)} m\n` +
      `t = ${f.t.toFixed(2)} s, H = ${f.energy.toExponential(4)} J\n` +
      `ω = ${f.omega.toFixed(2)} rad/s, R = ${f.radius.toPrecision(3)} m, λ = ${f.damping.toExponential(1)} N·m·s\n` +
      `centre (${f.centre.map((v) => v.toFixed(3)).join(", ")}) m\n` +
      `simulation: ${f.load === null ? "…" : (100 * f.load).toFixed(1)} % of a core, ${f.halved} steps halved`;
    if (options.has("selftest") || options.has("drag")) selftest(f);
  };
  socket.onclose = () => {
    $("status").textContent += frame ? "\n(disconnected: the server stopped)" : "\n(no connection: is the server running?)";
  };

  // After half a second: is the chain drawn where its positions say? Then a drag of the
  // pivot by (120, −60) px; a second later: has the centre gone where the drag says?
  const test = {};
  function selftest(f) {
    if (count === 30) {
      const r = canvas.getBoundingClientRect(), p = camera.project(point(f, 0));
      test.drawn = camera.inspect(points(f).slice(1));
      test.links = f.points.length / 3 - 1;
      test.before = f.centre;
      test.picture = { points: points(f), ...camera.picture() };
      test.drag = [120, -60];
      const at = (dx, dy) => ({ clientX: r.left + p[0] + dx, clientY: r.top + p[1] + dy, bubbles: true });
      canvas.dispatchEvent(new MouseEvent("mousedown", at(0, 0)));
      window.dispatchEvent(new MouseEvent("mousemove", at(60, -30)));
      window.dispatchEvent(new MouseEvent("mousemove", at(120, -60)));
      window.dispatchEvent(new MouseEvent("mouseup", at(120, -60)));
      test.dragged_at = f.t;
    } else if (test.dragged_at !== undefined && test.after === undefined && f.t > test.dragged_at + 1.5) {
      test.after = f.centre;
      test.target = f.target;
      test.pivot_on_screen = camera.project(point(f, 0)).slice(0, 2);
      test.drawn_after = camera.inspect(points(f).slice(1));
      test.errors = $("error").textContent;
      test.drags = drags;
      if (!options.has("selftest")) return;
      send({ selftest: test });
      const moved = Math.hypot(...test.after.map((v, k) => v - test.before[k]));
      $("selftest").textContent = `self-test sent to the server: the drag moved the pivot ${moved.toFixed(3)} m`;
      $("selftest").hidden = false;
    }
  }
})();
