// Arena's top-down view on an HTML canvas: one drawing for the live view and the replay.
//
// ArenaView draws a scene (map, obstacles, robot bodies) and frames (robot poses, plan, local
// path, subgoal, goal, lidar hits, people coloured by social state, groups and trails) as sent
// by arena.live.frame.scene_json / frame_json, in world metres with x right and y up. Between
// two frames it moves robots and people linearly, so a 10 Hz simulation looks smooth.
// ArenaLive connects a view to a run's live channel (WebSocket /api/runs/<run>/live) and sends
// the page's commands; ArenaReplay plays recorded frames with a time slider.
"use strict";

class ArenaView {
  constructor(canvas, options = {}) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d");
    this.trailLength = options.trailLength ?? 30;
    this.scene = null;
    this.prev = null;
    this.frame = null;
    this.arrived = 0;
    this.interval = 100;
    this.trails = new Map();
    this.mapImage = null;
    this.tool = null; // "goal" | "teleport" | null
    this.onPick = null; // called with {x, y, theta} when a goal or pose is picked
    this.drawn = 0; // frames received (tests and the page's rate display)
    this.pending = null;
    this._bindMouse();
    const loop = () => { this.render(); requestAnimationFrame(loop); };
    requestAnimationFrame(loop);
  }

  setScene(scene) {
    this.scene = scene;
    this.prev = this.frame = null;
    this.trails.clear();
    this.mapImage = null;
    const img = new Image();
    img.onload = () => { this.mapImage = img; };
    img.src = "data:image/png;base64," + scene.map.png;
    this._fit();
  }

  setFrame(frame, { jump = false } = {}) {
    const now = performance.now();
    if (this.frame && !jump) {
      this.interval = Math.min(500, Math.max(16, 0.7 * this.interval + 0.3 * (now - this.arrived)));
    }
    this.prev = jump ? frame : this.frame;
    this.frame = frame;
    this.arrived = now;
    this.drawn += 1;
    if (jump) this.trails.clear();
    const p = frame.people;
    for (let i = 0; i < p.id.length; i++) {
      const t = this.trails.get(p.id[i]) ?? [];
      t.push([p.x[i], p.y[i]]);
      if (t.length > this.trailLength) t.shift();
      this.trails.set(p.id[i], t);
    }
  }

  // -- coordinates ------------------------------------------------------------------------------
  _fit() {
    const m = this.scene.map;
    const w = m.width * m.resolution, h = m.height * m.resolution;
    const rect = this.canvas.getBoundingClientRect();
    const dpr = window.devicePixelRatio || 1;
    this.canvas.width = Math.round(rect.width * dpr);
    this.canvas.height = Math.round(rect.height * dpr);
    this.scale = Math.min(this.canvas.width / w, this.canvas.height / h);
    this.ox = m.origin[0] - (this.canvas.width / this.scale - w) / 2;
    this.oy = m.origin[1] - (this.canvas.height / this.scale - h) / 2;
  }

  toScreen(x, y) {
    return [(x - this.ox) * this.scale, this.canvas.height - (y - this.oy) * this.scale];
  }

  toWorld(px, py) {
    return [px / this.scale + this.ox, (this.canvas.height - py) / this.scale + this.oy];
  }

  _bindMouse() {
    let down = null;
    const world = (e) => {
      const r = this.canvas.getBoundingClientRect();
      const dpr = this.canvas.width / r.width;
      return this.toWorld((e.clientX - r.left) * dpr, (e.clientY - r.top) * dpr);
    };
    this.canvas.addEventListener("mousedown", (e) => {
      if (this.tool && this.scene) { down = world(e); this.pending = { from: down, to: down }; }
    });
    this.canvas.addEventListener("mousemove", (e) => {
      if (down) this.pending = { from: down, to: world(e) };
    });
    this.canvas.addEventListener("mouseup", (e) => {
      if (!down) return;
      const to = world(e);
      const dx = to[0] - down[0], dy = to[1] - down[1];
      // as RViz's 2D Nav Goal: click for the position, drag for the heading
      const theta = Math.hypot(dx, dy) > 0.15 ? Math.atan2(dy, dx) : 0.0;
      if (this.onPick) this.onPick({ x: down[0], y: down[1], theta });
      down = null;
      this.pending = null;
    });
  }

  // -- drawing ----------------------------------------------------------------------------------
  render() {
    const ctx = this.ctx;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = "#e8eaed";
    ctx.fillRect(0, 0, this.canvas.width, this.canvas.height);
    if (!this.scene) return;
    const s = this.scene;
    if (this.mapImage) {
      const [x0, y1] = this.toScreen(s.map.origin[0], s.map.origin[1] + s.map.height * s.map.resolution);
      ctx.imageSmoothingEnabled = false;
      ctx.drawImage(this.mapImage, x0, y1, s.map.width * s.map.resolution * this.scale,
                    s.map.height * s.map.resolution * this.scale);
    }
    ctx.fillStyle = "#b07a45";
    ctx.strokeStyle = "#6b4423";
    for (const poly of s.obstacles) this._polygon(poly, true);
    const f = this.frame;
    if (!f) return;
    const a = Math.min(1, (performance.now() - this.arrived) / this.interval);
    const prev = this.prev ?? f;
    this._trails(s);
    this._path(f.plan, "#2b6cb0", 2, []);
    this._path(f.local_path, "#38a169", 2, [6, 4]);
    if (f.scan.length) {
      ctx.fillStyle = "#e53e3e";
      const r = Math.max(1.5, 0.03 * this.scale);
      for (const [x, y] of f.scan) {
        const [px, py] = this.toScreen(x, y);
        ctx.fillRect(px - r / 2, py - r / 2, r, r);
      }
    }
    this._groups(f);
    this._people(prev, f, a, s);
    if (f.goal) this._goal(f.goal, "#2f855a");
    if (f.subgoal) this._marker(f.subgoal[0], f.subgoal[1], "#d69e2e", 6);
    for (let i = 0; i < f.poses.length; i++) {
      const p0 = prev.poses[i] ?? f.poses[i], p1 = f.poses[i];
      const pose = [lerp(p0[0], p1[0], a), lerp(p0[1], p1[1], a), lerpAngle(p0[2], p1[2], a)];
      this._robot(s.robots[i], pose, s.robot_colors[i % s.robot_colors.length],
                  f.collision[i] ? s.collision_color : null);
    }
    if (this.pending) {
      const { from, to } = this.pending;
      const theta = Math.hypot(to[0] - from[0], to[1] - from[1]) > 0.15
        ? Math.atan2(to[1] - from[1], to[0] - from[0]) : 0.0;
      this._goal([from[0], from[1], theta], this.tool === "goal" ? "#2f855a" : "#805ad5");
    }
  }

  _polygon(points, fill) {
    const ctx = this.ctx;
    ctx.beginPath();
    points.forEach(([x, y], i) => {
      const [px, py] = this.toScreen(x, y);
      if (i === 0) ctx.moveTo(px, py); else ctx.lineTo(px, py);
    });
    ctx.closePath();
    if (fill) ctx.fill();
    ctx.lineWidth = 1;
    ctx.stroke();
  }

  _path(points, colour, width, dash) {
    if (!points || points.length < 2) return;
    const ctx = this.ctx;
    ctx.save();
    ctx.strokeStyle = colour;
    ctx.lineWidth = width;
    ctx.setLineDash(dash);
    ctx.beginPath();
    points.forEach(([x, y], i) => {
      const [px, py] = this.toScreen(x, y);
      if (i === 0) ctx.moveTo(px, py); else ctx.lineTo(px, py);
    });
    ctx.stroke();
    ctx.restore();
  }

  _trails(s) {
    const ctx = this.ctx;
    ctx.save();
    ctx.strokeStyle = "rgba(120, 120, 120, 0.35)";
    ctx.lineWidth = 2;
    for (const t of this.trails.values()) {
      if (t.length < 2) continue;
      ctx.beginPath();
      t.forEach(([x, y], i) => {
        const [px, py] = this.toScreen(x, y);
        if (i === 0) ctx.moveTo(px, py); else ctx.lineTo(px, py);
      });
      ctx.stroke();
    }
    ctx.restore();
  }

  _groups(f) {
    const p = f.people, members = new Map();
    for (let i = 0; i < p.id.length; i++) {
      if (p.group[i] < 0) continue;
      if (!members.has(p.group[i])) members.set(p.group[i], []);
      members.get(p.group[i]).push([p.x[i], p.y[i]]);
    }
    const ctx = this.ctx;
    ctx.save();
    ctx.strokeStyle = "rgba(60, 60, 60, 0.55)";
    ctx.lineWidth = 1.5;
    ctx.setLineDash([3, 3]);
    for (const pts of members.values()) {
      if (pts.length < 2) continue;
      ctx.beginPath();
      pts.forEach(([x, y], i) => {
        const [px, py] = this.toScreen(x, y);
        if (i === 0) ctx.moveTo(px, py); else ctx.lineTo(px, py);
      });
      if (pts.length > 2) ctx.closePath();
      ctx.stroke();
    }
    ctx.restore();
  }

  _people(prev, f, a, s) {
    const ctx = this.ctx, p = f.people, q = prev.people;
    const before = new Map();
    for (let i = 0; i < q.id.length; i++) before.set(q.id[i], i);
    for (let i = 0; i < p.id.length; i++) {
      const j = before.get(p.id[i]);
      const x = j === undefined ? p.x[i] : lerp(q.x[j], p.x[i], a);
      const y = j === undefined ? p.y[i] : lerp(q.y[j], p.y[i], a);
      const [px, py] = this.toScreen(x, y);
      const r = Math.max(3, p.radius[i] * this.scale);
      ctx.beginPath();
      ctx.arc(px, py, r, 0, 2 * Math.PI);
      ctx.fillStyle = s.state_colors[p.state[i] % s.state_colors.length];
      ctx.fill();
      ctx.lineWidth = 1.4;
      ctx.strokeStyle = s.kind_colors[p.kind[i] % s.kind_colors.length];
      ctx.stroke();
      const h = p.heading[i];
      ctx.beginPath();
      ctx.moveTo(px, py);
      ctx.lineTo(px + r * Math.cos(h), py - r * Math.sin(h));
      ctx.stroke();
    }
  }

  _robot(robot, pose, colour, hit) {
    const c = Math.cos(pose[2]), sn = Math.sin(pose[2]);
    const pts = robot.footprint.map(([x, y]) => [pose[0] + c * x - sn * y, pose[1] + sn * x + c * y]);
    const ctx = this.ctx;
    ctx.save();
    ctx.fillStyle = colour + "cc";
    ctx.strokeStyle = hit ?? "#10131a";
    ctx.lineWidth = hit ? 3 : 1.5;
    this._polygon(pts, true);
    const reach = Math.max(...robot.footprint.map(([x, y]) => Math.hypot(x, y)));
    const [px, py] = this.toScreen(pose[0], pose[1]);
    const [hx, hy] = this.toScreen(pose[0] + reach * c, pose[1] + reach * sn);
    ctx.beginPath();
    ctx.moveTo(px, py);
    ctx.lineTo(hx, hy);
    ctx.stroke();
    ctx.restore();
  }

  _goal(g, colour) {
    this._marker(g[0], g[1], colour, 9);
    const ctx = this.ctx;
    const [px, py] = this.toScreen(g[0], g[1]);
    const len = Math.max(14, 0.6 * this.scale);
    ctx.save();
    ctx.strokeStyle = colour;
    ctx.lineWidth = 2.5;
    ctx.beginPath();
    ctx.moveTo(px, py);
    ctx.lineTo(px + len * Math.cos(g[2]), py - len * Math.sin(g[2]));
    ctx.stroke();
    ctx.restore();
  }

  _marker(x, y, colour, r) {
    const ctx = this.ctx;
    const [px, py] = this.toScreen(x, y);
    ctx.save();
    ctx.fillStyle = colour;
    ctx.strokeStyle = "#ffffff";
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    ctx.moveTo(px, py - r); ctx.lineTo(px + r, py); ctx.lineTo(px, py + r); ctx.lineTo(px - r, py);
    ctx.closePath();
    ctx.fill();
    ctx.stroke();
    ctx.restore();
  }
}

function lerp(a, b, t) { return a + (b - a) * t; }
function lerpAngle(a, b, t) {
  const d = Math.atan2(Math.sin(b - a), Math.cos(b - a));
  return a + d * t;
}

// A view fed by a run's live channel; commands go back on the same socket. Until the first
// scene arrives (a run or a benchmark's workers still starting) it tries again every second,
// for at most `patience` seconds; a channel that has shown an episode is not reopened.
class ArenaLive {
  constructor(view, url, status, patience = 120) {
    this.view = view;
    this.url = url;
    this.status = status; // called with each status, error and end message
    this.messages = 0;
    this.scenes = 0;
    this.deadline = Date.now() + 1000 * patience;
    view.onPick = (p) => this.send({ cmd: view.tool, x: p.x, y: p.y, theta: p.theta });
    this.connect();
  }

  connect() {
    this.ws = new WebSocket(this.url);
    this.ws.onmessage = (e) => {
      const m = JSON.parse(e.data);
      this.messages += 1;
      if (m.type === "scene") {
        this.scenes += 1;
        this.lastFrame = null; // the previous episode's
        this.view.setScene(m);
      }
      else if (m.type === "frame") this.view.setFrame(m);
      if (m.type === "closed" && this.scenes === 0 && Date.now() < this.deadline) {
        this.waiting = true;
        return; // not started yet: onclose tries again
      }
      if (m.type !== "frame" || m.outcome) this.status(m);
      if (m.type === "frame") this.lastFrame = m;
    };
    this.ws.onclose = () => {
      if (this.scenes === 0 && Date.now() < this.deadline) {
        setTimeout(() => this.connect(), 1000);
      } else {
        this.status({ type: "closed" });
      }
    };
  }

  send(message) {
    if (this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(message));
  }
}

// The links to a benchmark's worker channels (#arena-channels), kept up to date.
function arenaChannels(run, current) {
  const el = document.getElementById("arena-channels");
  if (!el) return;
  fetch("/api/runs/" + encodeURIComponent(run)).then((r) => r.ok ? r.json() : null).then((d) => {
    const names = (d && d.channels || []).filter((c) => c !== "live");
    el.replaceChildren();
    if (names.length) el.append("workers: ");
    names.forEach((name, i) => {
      const a = document.createElement("a");
      a.href = "/live/" + encodeURIComponent(run) + "?channel=" + encodeURIComponent(name);
      a.textContent = name.replace("_", " ");
      a.style.marginRight = "12px";
      if (name === current || (!current && i === 0)) a.style.fontWeight = "bold";
      el.append(a);
    });
  }).catch(() => {});
}

// Recorded frames played on a view, positioned by a slider (0 .. frames - 1).
class ArenaReplay {
  constructor(view, data, slider, label) {
    this.view = view;
    this.frames = data.frames;
    this.slider = slider;
    this.label = label;
    this.playing = false;
    view.setScene(data.scene);
    slider.max = String(this.frames.length - 1);
    slider.addEventListener("input", () => this.show(Number(slider.value), true));
    this.show(0, true);
  }

  show(k, jump) {
    this.k = Math.max(0, Math.min(this.frames.length - 1, k));
    const f = this.frames[this.k];
    this.view.setFrame(f, { jump });
    this.slider.value = String(this.k);
    this.label.textContent = `t = ${f.time.toFixed(1)} s  step ${f.step}` + (f.outcome ? `  ${f.outcome}` : "");
  }

  play() {
    if (this.playing) return;
    this.playing = true;
    const dt = 1000 * (this.view.scene.dt || 0.1);
    const tick = () => {
      if (!this.playing) return;
      if (this.k >= this.frames.length - 1) { this.playing = false; return; }
      this.show(this.k + 1, false);
      setTimeout(tick, dt);
    };
    tick();
  }

  pause() { this.playing = false; }
}

// The live page's status line (#arena-status): time, step, pace, people, the last error.
function arenaShowStatus(m) {
  const el = document.getElementById("arena-status");
  if (!el) return;
  const live = window.arenaLive;
  if (m.type === "status") live.state = m;
  if (m.type === "error") live.error = m.message;
  if (m.type === "closed") live.closed = m.message || "disconnected";
  if (m.type === "scene") live.title = m.title || "";
  const f = live.lastFrame, s = live.state;
  let text = f ? `t = ${f.time.toFixed(1)} s   step ${f.step}   people ${f.people.id.length}` : (live.waiting ? "waiting for the run to start (or it has ended)" : "waiting for the run");
  if (live.title) text = live.title + "   " + text;
  if (s) text += s.paused ? "   paused" : `   pace ${s.speed === 0 ? "max" : s.speed + "×"}`;
  if (f && f.outcome) text += `   episode ended: ${f.outcome}`;
  if (live.closed) text += `   (${live.closed})`;
  if (live.error) text += `   error: ${live.error}`;
  el.textContent = text;
}
setInterval(() => { if (window.arenaLive) arenaShowStatus({ type: "tick" }); }, 250);

// Run fn once the element with this id exists (NiceGUI mounts the page after the body's
// scripts run); the pages start their canvas this way, without a server round trip.
function arenaWhenReady(id, fn) {
  const el = document.getElementById(id);
  if (el) fn(el);
  else setTimeout(() => arenaWhenReady(id, fn), 20);
}

// The live page: the canvas fed by the run's live WebSocket.
function arenaStartLive(run, channel) {
  arenaChannels(run, channel);
  setInterval(() => arenaChannels(run, channel), 3000);
  arenaWhenReady("arena-canvas", (canvas) => {
    window.arenaView = new ArenaView(canvas);
    const scheme = location.protocol === "https:" ? "wss://" : "ws://";
    const query = channel ? "?channel=" + encodeURIComponent(channel) : "";
    window.arenaLive = new ArenaLive(window.arenaView,
      scheme + location.host + "/api/runs/" + encodeURIComponent(run) + "/live" + query,
      arenaShowStatus);
  });
}

// The replay page: fetch the record's frames; a failure is shown where the time would be.
function arenaStartReplay(run, record) {
  arenaWhenReady("arena-canvas", (canvas) => {
    window.arenaView = new ArenaView(canvas);
    const label = document.getElementById("arena-time");
    const url = "/api/runs/" + encodeURIComponent(run) + "/replay?record=" + encodeURIComponent(record);
    fetch(url)
      .then((r) => r.ok ? r.json() : r.json().then((d) => { throw new Error(d.detail || r.statusText); },
                                                        () => { throw new Error(r.statusText); }))
      .then((d) => {
        window.arenaReplay = new ArenaReplay(window.arenaView, d,
          document.getElementById("arena-slider"), label);
      })
      .catch((e) => { window.arenaReplayError = String(e.message || e); label.textContent = "error: " + window.arenaReplayError; });
  });
}

window.arenaWhenReady = arenaWhenReady;
window.arenaChannels = arenaChannels;
window.arenaStartLive = arenaStartLive;
window.arenaStartReplay = arenaStartReplay;
window.arenaShowStatus = arenaShowStatus;
window.ArenaView = ArenaView;
window.ArenaLive = ArenaLive;
window.ArenaReplay = ArenaReplay;
