// The scenario editor's side panels: the list of what the scenario holds and the fields of the
// selection (methods of ArenaEditor, editor.js; loaded after it).

Object.assign(ArenaEditor.prototype, {
  _message(text, bad = false) {
    const m = $("editor-message");
    m.textContent = text;
    m.className = bad ? "editor-note editor-bad" : "editor-note";
  },

  _renderList() {
    const s = this.scenario, rows = [];
    const item = (label, sel) => {
      const active = this.sel && JSON.stringify(this.sel) === JSON.stringify(sel);
      return el("li", { class: active ? "editor-active" : "", onclick: () => { this.sel = sel; this.changed(); } },
                [document.createTextNode(label)]);
    };
    s.robots.forEach((r, i) => {
      if (r.start) rows.push(item(`robot ${i} start`, { kind: "start", robot: i }));
      if (r.goal) rows.push(item(`robot ${i} goal`, { kind: "goal", robot: i }));
    });
    s.obstacles.dynamic.forEach((p, i) => rows.push(item(`${p.name} (${p.type || "adult"}, ${(p.waypoints || []).length} waypoints)`, { kind: "ped", index: i })));
    for (const group of ["static", "interactive"]) {
      s.obstacles[group].forEach((o, i) => rows.push(item(`${o.name} (${o.model}${group === "interactive" ? ", interactive" : ""})`, { kind: "obstacle", group, index: i })));
    }
    this.zones.forEach((z, i) => rows.push(item(`zone ${z.label}`, { kind: "zone", index: i })));
    $("editor-list").replaceChildren(...rows);
  },

  _renderProps() {
    const box = $("editor-props");
    box.replaceChildren();
    const item = this._selected(), sel = this.sel;
    if (!item) { box.append(el("div", { class: "editor-note", text: "Nothing selected." })); return; }
    const field = (label, value, onchange, attrs = {}) => {
      const input = el("input", { value: value ?? "", ...attrs });
      input.addEventListener("change", () => { onchange(input.value); this.changed(); });
      box.append(el("label", {}, [el("span", { text: label }), input]));
      return input;
    };
    const choice = (label, value, options, onchange) => {
      const select = el("select", {}, options.map(([v, t]) => el("option", { value: v, text: t })));
      select.value = value;
      select.addEventListener("change", () => { onchange(select.value); this.changed(); });
      box.append(el("label", {}, [el("span", { text: label }), select]));
    };
    const pose = (q, heading = true) => {
      field("x (m)", q[0], (v) => { q[0] = Number(v); }, { type: "number", step: "0.05" });
      field("y (m)", q[1], (v) => { q[1] = Number(v); }, { type: "number", step: "0.05" });
      if (heading) {
        field("θ (rad)", q.length > 2 ? q[2] : 0, (v) => { while (q.length < 3) q.push(0); q[2] = Number(v); },
              { type: "number", step: "0.05" });
      }
    };
    const remove = (label) => box.append(el("button", { class: "editor-button editor-danger", text: label,
                                                         onclick: () => this.removeSelected() }));
    if (sel.kind === "start" || sel.kind === "goal") {
      box.append(el("h4", { text: `robot ${sel.robot} ${sel.kind}` }));
      pose(item[sel.kind]);
      remove("remove robot");
    } else if (sel.kind === "ped" || sel.kind === "waypoint") {
      this._pedProps(box, item, field, choice, pose);
      remove(sel.kind === "waypoint" ? "remove waypoint" : "remove pedestrian");
    } else if (sel.kind === "group") {
      const members = this._groups().get(sel.group).map((i) => this.scenario.obstacles.dynamic[i]);
      box.append(el("h4", { text: `group ${sel.group}: ${members.length} pedestrians` }));
      choice("type", members[0].type || "adult", this.fields.types.map((t) => [t, t]),
             (v) => members.forEach((m) => { m.type = v; }));
      choice("waypoint mode", String(members[0].waypoint_mode ?? 0), [["0", "0 loop"], ["1", "1 random"]],
             (v) => members.forEach((m) => { m.waypoint_mode = Number(v); }));
      box.append(el("div", { class: "editor-note", text: "Waypoint tool: each click adds a waypoint to every member." }));
      remove("remove group");
    } else if (sel.kind === "obstacle") {
      box.append(el("h4", { text: `${sel.group} obstacle` }));
      field("name", item.name, (v) => { item.name = v; });
      choice("model", String(item.model).replace(/\.yaml$/, ""), Object.keys(this.library).map((m) => [m, m]), (v) => { item.model = v; });
      item.pos = item.pos || [0, 0, 0];
      pose(item.pos);
      remove("remove obstacle");
    } else if (sel.kind === "zone") {
      box.append(el("h4", { text: "zone" }));
      field("label", item.label, (v) => { item.label = v; });
      field("categories", [].concat(item.category || []).join(", "),
            (v) => { item.category = v.split(",").map((c) => c.trim()).filter(Boolean); });
      box.append(el("div", { class: "editor-note", text: `${this._zonePolygons(item).reduce((a, p) => a + p.length, 0)} corners; saved as the scenario's zones.yaml` }));
      remove("remove zone");
    }
  },

  _pedProps(box, ped, field, choice, pose) {
    const set = (key) => (v) => { const p = parseParam(v); if (p === undefined) delete ped[key]; else ped[key] = p; };
    box.append(el("h4", { text: "pedestrian" }));
    field("name", ped.name, (v) => { ped.name = v; });
    choice("type", ped.type || "adult", this.fields.types.map((t) => [t, t]), (v) => { ped.type = v; });
    field("model", ped.model || "actor1", (v) => { ped.model = v; });
    ped.pos = ped.pos || [0, 0, 0];
    pose(ped.pos, false);
    choice("waypoint mode", String(ped.waypoint_mode ?? 0), [["0", "0 loop"], ["1", "1 random"], ["2", "2 (read as loop)"]],
           (v) => { ped.waypoint_mode = Number(v); });
    field("vmax (m/s)", ped.vmax === undefined ? "" : [].concat(ped.vmax).join(", "), set("vmax"));
    choice("startup", ped.start_up_mode || "default", this.fields.startup_modes.map((m) => [m, m]),
           (v) => { ped.start_up_mode = v; });
    if (ped.start_up_mode === "wait_timer") field("wait time (s)", ped.wait_time, set("wait_time"));
    if (ped.start_up_mode === "trigger_zone") field("trigger radius (m)", ped.trigger_zone_radius, set("trigger_zone_radius"));
    const wps = ped.waypoints || [];
    box.append(el("div", { class: "editor-note", text: `${wps.length} waypoint(s): ${wps.map((w) => `(${w[0]}, ${w[1]})`).join(" → ") || "none (stands still)"}` }));
    // every other field of the format, named by the API (no list kept here)
    const shown = new Set(["name", "type", "model", "pos", "waypoint_mode", "vmax", "start_up_mode", "wait_time",
                           "trigger_zone_radius", "waypoints", "id"]);
    const more = el("details", {}, [el("summary", { text: "pedsim parameters (number or lo, hi)" })]);
    for (const [key, doc] of Object.entries(this.fields.pedestrian)) {
      if (shown.has(key)) continue;
      const input = el("input", { value: ped[key] === undefined ? "" : [].concat(ped[key]).join(", "), title: doc });
      input.addEventListener("change", () => { set(key)(input.value); this.changed(); });
      more.append(el("label", {}, [el("span", { text: key.replace(/_/g, " ") }), input]));
    }
    box.append(more);
  },

  // -- drawing ----------------------------------------------------------------------------------
});
