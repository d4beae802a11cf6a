// The scenario editor's canvas drawing and hit tests: map, zones, obstacles, people with their
// waypoints, robots, and what a click picks (methods of ArenaEditor, editor.js; loaded after
// it).

Object.assign(ArenaEditor.prototype, {
  _hit(p) {
    const s = this.scenario;
    for (let i = s.robots.length - 1; i >= 0; i--) {
      for (const key of ["goal", "start"]) {
        const q = s.robots[i][key];
        if (q && this._near(p, q, 14)) return { kind: key, robot: i };
      }
    }
    const d = s.obstacles.dynamic;
    for (let i = d.length - 1; i >= 0; i--) {
      const wps = d[i].waypoints || [];
      for (let j = wps.length - 1; j >= 0; j--) if (this._near(p, wps[j], 8)) return { kind: "waypoint", index: i, wp: j };
      const q = d[i].pos || [0, 0];
      if (Math.hypot(p[0] - q[0], p[1] - q[1]) <= PED_RADIUS || this._near(p, q, 8)) {
        const m = /^group(\d+)_\d+$/.exec(d[i].name || "");
        return m && $("editor-group-select").checked ? { kind: "group", group: m[1] } : { kind: "ped", index: i };
      }
    }
    for (const group of ["interactive", "static"]) {
      const list = s.obstacles[group];
      for (let i = list.length - 1; i >= 0; i--) {
        if (this._insideObstacle(p, list[i])) return { kind: "obstacle", group, index: i };
      }
    }
    for (let i = this.zones.length - 1; i >= 0; i--) {
      if (this._zonePolygons(this.zones[i]).some((poly) => pointInPolygon(p, poly))) return { kind: "zone", index: i };
    }
    return null;
  },

  _insideObstacle(p, o) {
    const poly = this._obstaclePolygon(o);
    return poly ? pointInPolygon(p, poly) : this._near(p, o.pos || [0, 0], 10);
  },

  _obstaclePolygon(o) {
    const lib = this.library[String(o.model || "").replace(/\.yaml$/, "")];
    if (!lib) return null;
    const [x, y, th] = [...(o.pos || [0, 0]), 0, 0];
    return lib.footprint.map((q) => { const r = rotate(q, th || 0); return [x + r[0], y + r[1]]; });
  },

  _zonePolygons(z) {
    const poly = z.polygon || [];
    return poly.length && typeof poly[0][0] === "number" ? [poly] : poly;
  },

  draw() {
    if (this._frame) return;
    this._frame = requestAnimationFrame(() => { this._frame = null; this._draw(); });
  },

  _draw() {
    const ctx = this.ctx;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = "#e8eaed";
    ctx.fillRect(0, 0, this.canvas.width, this.canvas.height);
    if (!this.map) return;
    const m = this.map;
    if (this.image) {
      const [x0, y1] = this.toScreen(m.origin[0], m.origin[1] + m.height * m.resolution);
      ctx.imageSmoothingEnabled = false;
      ctx.drawImage(this.image, x0, y1, m.width * m.resolution * this.view.scale, m.height * m.resolution * this.view.scale);
    }
    const flagged = this._flagged();
    const s = this.scenario, sel = this.sel;
    this.zones.forEach((z, i) => this._zone(z, sel && sel.kind === "zone" && sel.index === i));
    if (this.pendingZone) this._line(this.pendingZone, "#805ad5", 2, [5, 4], 4);
    for (const group of ["static", "interactive"]) {
      s.obstacles[group].forEach((o, i) => {
        const poly = this._obstaclePolygon(o);
        const chosen = sel && sel.kind === "obstacle" && sel.group === group && sel.index === i;
        ctx.fillStyle = group === "static" ? "#b07a45" : "#9f7aea";
        ctx.strokeStyle = flagged.has(`obstacles.${group}[${i}]`) ? "#e53e3e" : chosen ? "#1a202c" : "#6b4423";
        if (poly) this._polygon(poly, chosen ? 2.5 : 1);
      });
    }
    const selectedPeds = new Set(this._selectedPeds());
    s.obstacles.dynamic.forEach((p, i) => this._ped(p, selectedPeds.has(i), flagged.has(`obstacles.dynamic[${i}]`),
                                                     sel && sel.kind === "waypoint" && sel.index === i ? sel.wp : -1));
    s.robots.forEach((r, i) => {
      if (r.start) this._robot(r.start, "#2b6cb0", "start", sel && sel.kind === "start" && sel.robot === i, flagged.has(`robots[${i}].start`));
      if (r.goal) this._robot(r.goal, "#2f855a", "goal", sel && sel.kind === "goal" && sel.robot === i, flagged.has(`robots[${i}].goal`));
      if (r.start && r.goal) this._line([r.start, r.goal], "rgba(43, 108, 176, 0.5)", 1.5, [3, 5]);
    });
  },

  _px(v) { return v * (window.devicePixelRatio || 1); },

  _polygon(points, width = 1) {
    const ctx = this.ctx;
    ctx.beginPath();
    points.forEach(([x, y], i) => { const [px, py] = this.toScreen(x, y); if (i === 0) ctx.moveTo(px, py); else ctx.lineTo(px, py); });
    ctx.closePath();
    ctx.fill();
    ctx.lineWidth = this._px(width);
    ctx.stroke();
  },

  _line(points, colour, width, dash, dots = 0) {
    const ctx = this.ctx;
    ctx.save();
    ctx.strokeStyle = colour;
    ctx.fillStyle = colour;
    ctx.lineWidth = this._px(width);
    ctx.setLineDash(dash.map((d) => this._px(d)));
    ctx.beginPath();
    points.forEach(([x, y], i) => { const [px, py] = this.toScreen(x, y); if (i === 0) ctx.moveTo(px, py); else ctx.lineTo(px, py); });
    ctx.stroke();
    if (dots) for (const [x, y] of points) { const [px, py] = this.toScreen(x, y); ctx.fillRect(px - this._px(dots) / 2, py - this._px(dots) / 2, this._px(dots), this._px(dots)); }
    ctx.restore();
  },

  _zone(z, chosen) {
    const ctx = this.ctx;
    ctx.save();
    ctx.fillStyle = chosen ? "rgba(128, 90, 213, 0.25)" : "rgba(128, 90, 213, 0.12)";
    ctx.strokeStyle = "#805ad5";
    ctx.setLineDash([this._px(6), this._px(4)]);
    for (const poly of this._zonePolygons(z)) this._polygon(poly, chosen ? 2 : 1);
    const first = this._zonePolygons(z)[0];
    if (first && first.length) {
      const [px, py] = this.toScreen(first[0][0], first[0][1]);
      ctx.fillStyle = "#553c9a";
      ctx.font = `${this._px(12)}px sans-serif`;
      ctx.fillText(`${z.label} (${[].concat(z.category || []).join(", ")})`, px + this._px(4), py - this._px(4));
    }
    ctx.restore();
  },

  _ped(p, chosen, bad, wpChosen) {
    const ctx = this.ctx;
    const pos = p.pos || [0, 0];
    const wps = p.waypoints || [];
    const colour = KIND_COLORS[String(p.type || "adult").replace(/^human\//, "")] || KIND_COLORS.adult;
    if (wps.length) {
      const route = [pos, ...wps];
      if ((p.waypoint_mode ?? 0) !== 1 && wps.length > 1) route.push(wps[0]); // a loop returns
      this._line(route, chosen ? colour : "rgba(90, 90, 90, 0.55)", chosen ? 2 : 1.2, [5, 4]);
      wps.forEach(([x, y], j) => {
        const [px, py] = this.toScreen(x, y);
        const r = this._px(j === wpChosen ? 6 : 4.5);
        ctx.fillStyle = j === wpChosen ? "#1a202c" : colour;
        ctx.fillRect(px - r, py - r, 2 * r, 2 * r);
        ctx.fillStyle = "#fff";
        ctx.font = `${this._px(9)}px sans-serif`;
        ctx.fillText(String(j + 1), px - this._px(2.5), py + this._px(3));
      });
    }
    const [px, py] = this.toScreen(pos[0], pos[1]);
    const r = Math.max(this._px(4), PED_RADIUS * this.view.scale);
    if (p.start_up_mode === "trigger_zone" && typeof p.trigger_zone_radius === "number") {
      ctx.save();
      ctx.strokeStyle = colour;
      ctx.setLineDash([this._px(2), this._px(3)]);
      ctx.beginPath();
      ctx.arc(px, py, p.trigger_zone_radius * this.view.scale, 0, 2 * Math.PI);
      ctx.stroke();
      ctx.restore();
    }
    ctx.beginPath();
    ctx.arc(px, py, r, 0, 2 * Math.PI);
    ctx.fillStyle = colour;
    ctx.fill();
    ctx.lineWidth = this._px(bad ? 3 : chosen ? 2.5 : 1);
    ctx.strokeStyle = bad ? "#e53e3e" : chosen ? "#1a202c" : "#fff";
    ctx.stroke();
  },

  _robot(q, colour, label, chosen, bad) {
    const ctx = this.ctx;
    const [x, y] = q, th = q.length > 2 ? q[2] : 0;
    const fp = this.robot && this.robot.footprint;
    ctx.save();
    ctx.globalAlpha = 0.85;
    ctx.fillStyle = colour;
    ctx.strokeStyle = bad ? "#e53e3e" : chosen ? "#1a202c" : "#fff";
    if (fp) this._polygon(fp.map((p) => { const r = rotate(p, th); return [x + r[0], y + r[1]]; }), bad ? 3 : chosen ? 2.5 : 1);
    else {
      const [px, py] = this.toScreen(x, y);
      ctx.beginPath();
      ctx.arc(px, py, Math.max(this._px(5), (this.robot ? this.robot.radius : 0.3) * this.view.scale), 0, 2 * Math.PI);
      ctx.fill();
      ctx.lineWidth = this._px(bad ? 3 : chosen ? 2.5 : 1);
      ctx.stroke();
    }
    ctx.restore();
    const reach = Math.max(0.5, (this.robot ? this.robot.radius : 0.3) * 1.8);
    const tip = [x + reach * Math.cos(th), y + reach * Math.sin(th)];
    this._line([[x, y], tip], colour, 2.5, []);
    const [px, py] = this.toScreen(x, y);
    ctx.fillStyle = "#1a202c";
    ctx.font = `bold ${this._px(12)}px sans-serif`;
    ctx.fillText(label, px + this._px(8), py - this._px(8));
  },
});

function pointInPolygon([x, y], poly) {
  let inside = false;
  for (let i = 0, j = poly.length - 1; i < poly.length; j = i++) {
    const [xi, yi] = poly[i], [xj, yj] = poly[j];
    if ((yi > y) !== (yj > y) && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) inside = !inside;
  }
  return inside;
}
