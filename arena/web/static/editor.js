// Arena's scenario editor: a top-down canvas on which an Arena scenario JSON is drawn and edited.
//
// The page (arena/web/editor.py) holds only the HTML; this script fetches everything from the
// editor's REST API (arena/web/api_editor.py) itself, so the first drawing needs no NiceGUI
// round trip. World coordinates are metres with x right and y up; headings are radians. The
// scenario is kept as the very JSON the file holds (keys the editor does not know stay as they
// are), and every change is sent to /api/scenarios/validate, whose problems and warnings are
// listed beside the canvas and marked on it.
//
// The class's side panels and drawing are in editor_panels.js and editor_draw.js (loaded after
// this file, they add methods to ArenaEditor).
//
// The format has no group key (Arena's crowd forms groups itself): the group tool places several
// pedestrians around one point that share their waypoints (each at its offset), named
// group<k>_<j>; a file's pedestrians named that way are one group again when it is loaded.
"use strict";

const PED_RADIUS = 0.3; // m, arena.tasks.scenario_checks.DEFAULT_PED_RADIUS
const GROUP_RING = 0.7; // m, distance of a group member from the group's centre
const DRAG_HEADING = 0.15; // m, a drag shorter than this sets no heading
const KIND_COLORS = { adult: "#3182ce", elder: "#d69e2e", child: "#38a169" };
const TOOL_HINTS = {
  select: "Click an item to select it, drag to move it. Keys: r / R rotate 15°, Delete removes.",
  start: "Click the robot's start; drag from it to give the heading.",
  goal: "Click the robot's goal; drag from it to give the heading.",
  pedestrian: "Click to place a pedestrian, then click its waypoints (Esc: done).",
  waypoint: "Click to add a waypoint to the selected pedestrian or group (Esc: done).",
  group: "Click to place a group; then click its shared waypoints (Esc: done).",
  obstacle: "Click to place the chosen obstacle; drag from it to rotate it.",
  zone: "Click the zone's corners; click the first corner again (or press Enter) to close it.",
};

const $ = (id) => document.getElementById(id);

async function api(method, url, body) {
  const init = { method, headers: {} };
  if (body instanceof FormData) init.body = body;
  else if (body !== undefined) {
    init.body = JSON.stringify(body);
    init.headers["Content-Type"] = "application/json";
  }
  const res = await fetch(url, init);
  let data = null;
  try { data = await res.json(); } catch (e) { data = null; }
  if (!res.ok) {
    const detail = data && typeof data.detail === "string" ? data.detail : `${res.status} ${res.statusText}`;
    throw new Error(detail);
  }
  return data;
}

function el(tag, attrs = {}, children = []) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === "text") e.textContent = v;
    else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
}

function emptyScenario() {
  return { robots: [], obstacles: { static: [], interactive: [], dynamic: [] } };
}

function rotate([x, y], a) {
  const c = Math.cos(a), s = Math.sin(a);
  return [c * x - s * y, s * x + c * y];
}

function round(v) { return Math.round(v * 1000) / 1000; }

// "0.3" -> 0.3, "0.3, 0.5" -> [0.3, 0.5], "" -> undefined; anything else stays text so that the
// validation names it.
function parseParam(text) {
  const t = text.trim();
  if (t === "") return undefined;
  const parts = t.replace(/^\[|\]$/g, "").split(",").map((s) => s.trim());
  const nums = parts.map(Number);
  if (parts.every((p) => p !== "") && nums.every(Number.isFinite)) {
    return nums.length === 1 ? nums[0] : nums;
  }
  return t;
}

class ArenaEditor {
  constructor() {
    this.canvas = $("editor-canvas");
    this.ctx = this.canvas.getContext("2d");
    this.mapRef = null; // {kind: "world" | "saved", name}
    this.map = null; // {width, height, resolution, origin, png}
    this.image = null;
    this.scenario = emptyScenario();
    this.zones = [];
    this.sel = null; // {kind: start|goal|ped|waypoint|obstacle|zone|group, ...}
    this.tool = "select";
    this.pendingZone = null; // [[x, y], ...] while drawing a zone
    this.drag = null;
    this.view = { scale: 1, ox: 0, oy: 0 };
    this.robot = null; // {name, radius, footprint}
    this.library = {}; // obstacle model -> {footprint, description}
    this.fields = null;
    this.validation = null;
    this.validated = 0; // answers shown (tests wait for it)
    this.checking = false; // a change awaits its validation
    this._seq = 0;
    this._timer = null;
    this._bind();
    new ResizeObserver(() => { this._fit(); this.draw(); }).observe(this.canvas);
  }

  // -- start ------------------------------------------------------------------------------------
  async start(options) {
    try {
      const [worlds, generators, obstacles, fields, saved, maps] = await Promise.all([
        api("GET", "/api/worlds"), api("GET", "/api/generators"), api("GET", "/api/obstacles"),
        api("GET", "/api/scenario_fields"), api("GET", "/api/scenarios"), api("GET", "/api/maps")]);
      this.fields = fields;
      for (const o of obstacles) this.library[o.name] = o;
      this._fillWorlds(worlds);
      this._fillGenerators(generators);
      this._fillSelect($("editor-obstacle-model"), obstacles.map((o) => [o.name, `${o.name} – ${o.description}`]));
      this._fillSelect($("editor-open"), saved.map((n) => [n, n]));
      this._fillSelect($("editor-saved-map"), maps.map((n) => [n, n]));
      this._fillSelect($("editor-ped-type"), fields.types.map((t) => [t, t]));
      if (options.load) await this.openSaved(options.load);
      else await this.loadWorld($("editor-world").value, "");
      this.ready = true;
    } catch (e) {
      this._message(`could not start the editor: ${e.message}`, true);
    }
  }

  _fillSelect(select, items) {
    select.replaceChildren(...items.map(([v, label]) => el("option", { value: v, text: label })));
  }

  _fillWorlds(worlds) {
    this.worlds = worlds;
    this._fillSelect($("editor-world"), worlds.map((w) => [w.name, w.name]));
    const small = worlds.find((w) => w.name === "small_office");
    if (small) $("editor-world").value = small.name;
    const scenarios = () => {
      const w = worlds.find((x) => x.name === $("editor-world").value);
      this._fillSelect($("editor-world-scenario"),
        [["", "empty scenario"], ...(w ? w.scenarios : []).map((s) => [s, `scenario ${s}`])]);
    };
    $("editor-world").addEventListener("change", scenarios);
    scenarios();
  }

  _fillGenerators(generators) {
    this.generators = generators;
    this._fillSelect($("editor-generator"), generators.map((g) => [g.name, g.name]));
    const form = () => {
      const g = generators.find((x) => x.name === $("editor-generator").value);
      const box = $("editor-gen-form");
      box.replaceChildren();
      if (!g) return;
      box.append(el("div", { class: "editor-note", text: g.summary }));
      for (const [key, prop] of Object.entries(g.schema.properties || {})) {
        const input = prop.enum
          ? el("select", { "data-param": key }, prop.enum.map((v) => el("option", { value: v, text: v })))
          : el("input", { "data-param": key, type: "number", step: "any" });
        if (prop.default !== undefined) input.value = prop.default;
        input.dataset.kind = prop.type || "string";
        box.append(el("label", { title: prop.description || "" }, [
          el("span", { text: key }), input,
          el("small", { text: prop.description || "" })]));
      }
    };
    $("editor-generator").addEventListener("change", form);
    form();
  }

  // -- maps -------------------------------------------------------------------------------------
  setMap(ref, map) {
    this.mapRef = ref;
    this.map = map;
    this.image = null;
    const img = new Image();
    img.onload = () => { this.image = img; this.draw(); };
    img.src = "data:image/png;base64," + map.png;
    $("editor-map-label").textContent = ref.kind === "world" ? `world ${ref.name}` : `map _maps/${ref.name}`;
    this._fit();
  }

  async loadWorld(world, scenarioName) {
    const data = await api("GET", `/api/worlds/${encodeURIComponent(world)}`);
    this.setMap({ kind: "world", name: world }, data.map);
    let scenario = emptyScenario();
    if (scenarioName) {
      scenario = (await api("GET", `/api/worlds/${encodeURIComponent(world)}/scenarios/${encodeURIComponent(scenarioName)}`)).scenario;
    }
    this.setScenario(scenario, data.zones || []);
  }

  async generate() {
    const params = {};
    for (const input of $("editor-gen-form").querySelectorAll("[data-param]")) {
      if (input.value === "") continue;
      const kind = input.dataset.kind;
      params[input.dataset.param] = kind === "integer" ? parseInt(input.value, 10)
        : kind === "number" ? parseFloat(input.value) : input.value;
    }
    const body = { generator: $("editor-generator").value, params,
                   seed: parseInt($("editor-seed").value || "0", 10) };
    const name = $("editor-map-name").value.trim();
    if (name) body.name = name;
    await this._newMap(() => api("POST", "/api/maps/generate", body));
  }

  async upload() {
    const form = new FormData();
    const yaml = $("editor-upload-yaml").files[0], image = $("editor-upload-image").files[0];
    if (!yaml || !image) { this._message("choose a map.yaml and its image", true); return; }
    form.append("yaml", yaml);
    form.append("image", image);
    form.append("name", $("editor-map-name").value.trim() || "uploaded");
    await this._newMap(() => api("POST", "/api/maps/upload", form));
  }

  async _newMap(request) {
    this._message("building the map…");
    try {
      const data = await request();
      this.setMap(data.ref, data.map);
      this._message(`map saved as _maps/${data.ref.name}`);
      this.setScenario(this.scenario, this.zones);
    } catch (e) {
      this._message(e.message, true);
    }
  }

  async loadSavedMap(name) {
    try {
      const data = await api("GET", `/api/maps/${encodeURIComponent(name)}`);
      this.setMap(data.ref, data.map);
      this.setScenario(this.scenario, this.zones);
    } catch (e) { this._message(e.message, true); }
  }

  async openSaved(name) {
    try {
      const data = await api("GET", `/api/scenarios/${encodeURIComponent(name)}`);
      const path = data.map.kind === "world" ? `/api/worlds/${encodeURIComponent(data.map.name)}`
        : `/api/maps/${encodeURIComponent(data.map.name)}`;
      const m = await api("GET", path);
      this.setMap(data.map, m.map);
      this.setScenario(data.scenario, data.zones || []);
      $("editor-name").value = name;
      this._message(`opened ${name}`);
    } catch (e) { this._message(e.message, true); }
  }

  setScenario(scenario, zones) {
    const s = JSON.parse(JSON.stringify(scenario));
    s.robots = s.robots || [];
    s.obstacles = s.obstacles || {};
    for (const g of ["static", "interactive", "dynamic"]) s.obstacles[g] = s.obstacles[g] || [];
    this.scenario = s;
    this.zones = JSON.parse(JSON.stringify(zones || []));
    this.sel = null;
    this.changed();
  }

  // -- saving -----------------------------------------------------------------------------------
  async save() {
    const name = $("editor-name").value.trim();
    const out = $("editor-save-result");
    out.className = "editor-note";
    try {
      const res = await api("PUT", `/api/scenarios/${encodeURIComponent(name)}`, this._request());
      out.textContent = `saved ${res.path} — run it: ${res.command}`;
      out.dataset.saved = res.path;
      const open = $("editor-open");
      if (![...open.options].some((o) => o.value === name)) open.append(el("option", { value: name, text: name }));
    } catch (e) {
      out.textContent = e.message;
      out.className = "editor-note editor-bad";
    }
  }

  _request() {
    return { scenario: this.scenario, map: this.mapRef, zones: this.zones };
  }

  // -- validation -------------------------------------------------------------------------------
  changed() {
    // an answer to an older state must not be shown (nor counted) once this one is pending
    this._seq += 1;
    this.checking = true;
    this._renderProps();
    this._renderList();
    this.draw();
    clearTimeout(this._timer);
    this._timer = setTimeout(() => this.validate(), 200);
  }

  async validate() {
    if (!this.mapRef) return;
    const seq = this._seq;
    $("editor-status").textContent = "checking…";
    let result;
    try {
      result = await api("POST", "/api/scenarios/validate", this._request());
    } catch (e) {
      result = { ok: false, problems: [{ path: null, message: e.message }], warnings: [] };
    }
    if (seq !== this._seq) return; // a newer change is being checked
    this.validation = result;
    this.checking = false;
    if (result.robot) this.robot = result.robot;
    this.validated += 1;
    const status = $("editor-status");
    status.textContent = result.ok
      ? (result.warnings.length ? `OK, ${result.warnings.length} warning(s)` : "OK")
      : `${result.problems.length} problem(s)`;
    status.className = result.ok ? "editor-ok" : "editor-bad";
    this._fillFindings($("editor-problems"), result.problems);
    this._fillFindings($("editor-warnings"), result.warnings);
    this.draw();
  }

  _fillFindings(list, findings) {
    list.replaceChildren(...findings.map((f) => el("li", {}, [
      el("code", { text: f.path || "scenario" }), document.createTextNode(" " + f.message)])));
  }

  _flagged() {
    const out = new Set();
    for (const f of (this.validation ? this.validation.problems : [])) {
      const m = /^(robots\[\d+\]\.(?:start|goal)|obstacles\.\w+\[\d+\])/.exec(f.path || "");
      if (m) out.add(m[1]);
    }
    return out;
  }

  // -- coordinates ------------------------------------------------------------------------------
  _fit() {
    const rect = this.canvas.getBoundingClientRect();
    const dpr = window.devicePixelRatio || 1;
    this.canvas.width = Math.max(1, Math.round(rect.width * dpr));
    this.canvas.height = Math.max(1, Math.round(rect.height * dpr));
    if (!this.map) return;
    const m = this.map;
    const w = m.width * m.resolution, h = m.height * m.resolution;
    const scale = 0.96 * Math.min(this.canvas.width / w, this.canvas.height / h);
    this.view = { scale, ox: m.origin[0] - (this.canvas.width / scale - w) / 2,
                  oy: m.origin[1] - (this.canvas.height / scale - h) / 2 };
  }

  toScreen(x, y) {
    const v = this.view;
    return [(x - v.ox) * v.scale, this.canvas.height - (y - v.oy) * v.scale];
  }

  toWorld(px, py) {
    const v = this.view;
    return [px / v.scale + v.ox, (this.canvas.height - py) / v.scale + v.oy];
  }

  // CSS pixels in the page of a world point (the browser tests click there).
  pageOf(x, y) {
    const r = this.canvas.getBoundingClientRect();
    const [px, py] = this.toScreen(x, y);
    const dpr = this.canvas.width / r.width;
    return [r.left + px / dpr, r.top + py / dpr];
  }

  _eventWorld(e) {
    const r = this.canvas.getBoundingClientRect();
    const dpr = this.canvas.width / r.width;
    return this.toWorld((e.clientX - r.left) * dpr, (e.clientY - r.top) * dpr);
  }

  // -- input ------------------------------------------------------------------------------------
  _bind() {
    for (const b of document.querySelectorAll("[data-tool]")) {
      b.addEventListener("click", () => this.setTool(b.dataset.tool));
    }
    $("editor-load-world").addEventListener("click", () =>
      this.loadWorld($("editor-world").value, $("editor-world-scenario").value)
        .catch((e) => this._message(e.message, true)));
    $("editor-generate").addEventListener("click", () => this.generate());
    $("editor-upload").addEventListener("click", () => this.upload());
    $("editor-load-map").addEventListener("click", () => this.loadSavedMap($("editor-saved-map").value));
    $("editor-save").addEventListener("click", () => this.save());
    $("editor-open-button").addEventListener("click", () => this.openSaved($("editor-open").value));
    for (const radio of document.querySelectorAll("input[name=editor-source]")) {
      radio.addEventListener("change", () => this._showSource());
    }
    this._showSource();
    const c = this.canvas;
    c.addEventListener("mousedown", (e) => this._down(e));
    c.addEventListener("mousemove", (e) => this._move(e));
    window.addEventListener("mouseup", (e) => this._up(e));
    c.addEventListener("wheel", (e) => {
      e.preventDefault();
      const [x, y] = this._eventWorld(e);
      const k = Math.exp(-e.deltaY * 0.0015);
      const v = this.view;
      v.ox = x - (x - v.ox) / k;
      v.oy = y - (y - v.oy) / k;
      v.scale *= k;
      this.draw();
    }, { passive: false });
    window.addEventListener("keydown", (e) => this._key(e));
  }

  _showSource() {
    const chosen = document.querySelector("input[name=editor-source]:checked").value;
    for (const box of document.querySelectorAll("[data-source]")) {
      box.style.display = box.dataset.source.split(" ").includes(chosen) ? "" : "none";
    }
  }

  setTool(tool) {
    this.tool = tool;
    this.pendingZone = null;
    for (const b of document.querySelectorAll("[data-tool]")) {
      b.classList.toggle("editor-active", b.dataset.tool === tool);
    }
    $("editor-hint").textContent = TOOL_HINTS[tool] || "";
    this.draw();
  }

  _key(e) {
    if (["INPUT", "SELECT", "TEXTAREA"].includes(document.activeElement.tagName)) return;
    if (e.key === "Escape") this.setTool("select");
    else if (e.key === "Enter" && this.pendingZone) this._closeZone();
    else if ((e.key === "Delete" || e.key === "Backspace") && this.sel) this.removeSelected();
    else if ((e.key === "r" || e.key === "R") && this.sel) {
      this._rotateSelected((e.key === "r" ? 1 : -1) * Math.PI / 12);
    }
  }

  _down(e) {
    if (!this.map || e.button !== 0) return;
    const p = this._eventWorld(e);
    const s = this.scenario;
    if (this.tool === "select") {
      this.sel = this._hit(p);
      this.drag = this.sel ? { mode: "move", last: p } : null;
      this.changed();
      return;
    }
    if (this.tool === "start" || this.tool === "goal") {
      if (!s.robots.length) s.robots.push({});
      const key = this.tool;
      s.robots[0][key] = [round(p[0]), round(p[1]), 0];
      this.sel = { kind: key, robot: 0 };
      this.drag = { mode: "heading", from: p };
    } else if (this.tool === "pedestrian") {
      s.obstacles.dynamic.push(this._newPed(p, this._freeName("ped")));
      this.sel = { kind: "ped", index: s.obstacles.dynamic.length - 1 };
      this.setTool("waypoint");
    } else if (this.tool === "group") {
      const n = Math.max(2, Math.min(8, parseInt($("editor-group-size").value || "3", 10)));
      const k = this._freeGroup();
      for (let j = 0; j < n; j++) {
        const off = rotate([GROUP_RING, 0], (2 * Math.PI * j) / n);
        s.obstacles.dynamic.push(this._newPed([p[0] + off[0], p[1] + off[1]], `group${k}_${j + 1}`));
      }
      this.sel = { kind: "group", group: k };
      this.setTool("waypoint");
    } else if (this.tool === "waypoint") {
      this._addWaypoint(p);
    } else if (this.tool === "obstacle") {
      const model = $("editor-obstacle-model").value;
      const group = $("editor-obstacle-interactive").checked ? "interactive" : "static";
      s.obstacles[group].push({ name: this._freeName(model), model, pos: [round(p[0]), round(p[1]), 0] });
      this.sel = { kind: "obstacle", group, index: s.obstacles[group].length - 1 };
      this.drag = { mode: "heading", from: p };
    } else if (this.tool === "zone") {
      const first = this.pendingZone && this.pendingZone[0];
      if (first && this.pendingZone.length >= 3 && this._near(p, first)) { this._closeZone(); return; }
      this.pendingZone = this.pendingZone || [];
      this.pendingZone.push([round(p[0]), round(p[1])]);
      this.draw();
      return;
    }
    this.changed();
  }

  _move(e) {
    if (!this.drag || !this.sel) return;
    const p = this._eventWorld(e);
    if (this.drag.mode === "heading") {
      const dx = p[0] - this.drag.from[0], dy = p[1] - this.drag.from[1];
      if (Math.hypot(dx, dy) > DRAG_HEADING) this._setHeading(round(Math.atan2(dy, dx)));
    } else {
      this._moveSelected(p[0] - this.drag.last[0], p[1] - this.drag.last[1]);
      this.drag.last = p;
    }
    this.drag.moved = true;
    this.draw();
  }

  _up() {
    if (this.drag && this.drag.moved) this.changed();
    this.drag = null;
  }

  _near(p, q, px = 9) {
    return Math.hypot(p[0] - q[0], p[1] - q[1]) * this.view.scale <= px * (window.devicePixelRatio || 1);
  }

  _newPed(p, name) {
    const ped = { name, pos: [round(p[0]), round(p[1]), 0], type: $("editor-ped-type").value || "adult",
                  model: "actor1", waypoints: [], waypoint_mode: 0 };
    return ped;
  }

  _freeName(base) {
    const taken = new Set(["static", "interactive", "dynamic"].flatMap((g) => this.scenario.obstacles[g].map((o) => o.name)));
    let i = 1;
    while (taken.has(`${base}_${i}`)) i += 1;
    return `${base}_${i}`;
  }

  _groups() {
    const groups = new Map();
    this.scenario.obstacles.dynamic.forEach((p, i) => {
      const m = /^group(\d+)_\d+$/.exec(p.name || "");
      if (m) groups.set(m[1], [...(groups.get(m[1]) || []), i]);
    });
    return groups;
  }

  _freeGroup() {
    const groups = this._groups();
    let k = 1;
    while (groups.has(String(k))) k += 1;
    return String(k);
  }

  _selectedPeds() {
    if (!this.sel) return [];
    if (this.sel.kind === "ped" || this.sel.kind === "waypoint") return [this.sel.index];
    if (this.sel.kind === "group") return this._groups().get(this.sel.group) || [];
    return [];
  }

  _addWaypoint(p) {
    const peds = this._selectedPeds();
    if (!peds.length) { this._message("select a pedestrian or a group first", true); return; }
    const d = this.scenario.obstacles.dynamic;
    // a group's members keep their offsets from the group's centre at every waypoint
    const cx = peds.reduce((a, i) => a + d[i].pos[0], 0) / peds.length;
    const cy = peds.reduce((a, i) => a + d[i].pos[1], 0) / peds.length;
    for (const i of peds) {
      const dx = peds.length > 1 ? d[i].pos[0] - cx : 0, dy = peds.length > 1 ? d[i].pos[1] - cy : 0;
      d[i].waypoints = [...(d[i].waypoints || []), [round(p[0] + dx), round(p[1] + dy), 0]];
    }
  }

  _closeZone() {
    const poly = this.pendingZone;
    this.pendingZone = null;
    if (!poly || poly.length < 3) return;
    this.zones.push({ label: `zone ${this.zones.length + 1}`, category: ["public"], polygon: poly });
    this.sel = { kind: "zone", index: this.zones.length - 1 };
    this.setTool("select");
    this.changed();
  }

  // -- selection --------------------------------------------------------------------------------
  _selected() {
    const s = this.scenario, sel = this.sel;
    if (!sel) return null;
    if (sel.kind === "start" || sel.kind === "goal") return s.robots[sel.robot] && s.robots[sel.robot][sel.kind] ? s.robots[sel.robot] : null;
    if (sel.kind === "ped" || sel.kind === "waypoint") return s.obstacles.dynamic[sel.index] || null;
    if (sel.kind === "obstacle") return s.obstacles[sel.group][sel.index] || null;
    if (sel.kind === "zone") return this.zones[sel.index] || null;
    if (sel.kind === "group") return (this._groups().get(sel.group) || []).length ? sel : null;
    return null;
  }

  _moveSelected(dx, dy) {
    const sel = this.sel, item = this._selected();
    if (!item) return;
    const shift = (q) => { q[0] = round(q[0] + dx); q[1] = round(q[1] + dy); };
    if (sel.kind === "start" || sel.kind === "goal") shift(item[sel.kind]);
    else if (sel.kind === "waypoint") shift(item.waypoints[sel.wp]);
    else if (sel.kind === "ped" || sel.kind === "obstacle") { item.pos = item.pos || [0, 0, 0]; shift(item.pos); }
    else if (sel.kind === "zone") for (const poly of this._zonePolygons(item)) poly.forEach(shift);
    else if (sel.kind === "group") {
      for (const i of this._groups().get(sel.group)) {
        const p = this.scenario.obstacles.dynamic[i];
        shift(p.pos);
        (p.waypoints || []).forEach(shift);
      }
    }
  }

  _setHeading(theta) {
    const sel = this.sel, item = this._selected();
    if (!item) return;
    const q = sel.kind === "start" || sel.kind === "goal" ? item[sel.kind]
      : sel.kind === "obstacle" || sel.kind === "ped" ? item.pos : null;
    if (!q) return;
    while (q.length < 3) q.push(0);
    q[2] = theta;
  }

  _rotateSelected(da) {
    const sel = this.sel, item = this._selected();
    if (!item) return;
    const q = sel.kind === "start" || sel.kind === "goal" ? item[sel.kind]
      : sel.kind === "obstacle" || sel.kind === "ped" ? item.pos : null;
    if (!q) return;
    const th = q.length > 2 ? q[2] : 0;
    this._setHeading(round(Math.atan2(Math.sin(th + da), Math.cos(th + da))));
    this.changed();
  }

  removeSelected() {
    const sel = this.sel, s = this.scenario;
    if (!this._selected()) return;
    if (sel.kind === "start" || sel.kind === "goal") s.robots.splice(sel.robot, 1);
    else if (sel.kind === "ped") s.obstacles.dynamic.splice(sel.index, 1);
    else if (sel.kind === "waypoint") s.obstacles.dynamic[sel.index].waypoints.splice(sel.wp, 1);
    else if (sel.kind === "obstacle") s.obstacles[sel.group].splice(sel.index, 1);
    else if (sel.kind === "zone") this.zones.splice(sel.index, 1);
    else if (sel.kind === "group") {
      const drop = new Set(this._groups().get(sel.group));
      s.obstacles.dynamic = s.obstacles.dynamic.filter((_, i) => !drop.has(i));
    }
    this.sel = null;
    this.changed();
  }

  // the side panels: editor_panels.js; drawing and hit tests: editor_draw.js
}

function arenaStartEditor(options) {
  const start = () => {
    window.arenaEditor = new ArenaEditor();
    window.arenaEditor.setTool("select");
    window.arenaEditor.start(options || {});
  };
  start();
}

// NiceGUI mounts the page's HTML after its scripts run: wait for the last element.
function arenaWhenEditorReady(fn) {
  if (document.getElementById("editor-list")) fn();
  else setTimeout(() => arenaWhenEditorReady(fn), 20);
}
