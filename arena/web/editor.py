"""The scenario editor page (``/editor``; ``?load=NAME`` opens a saved scenario).

The page is plain HTML around one canvas; ``static/editor.js`` fetches the maps, the obstacle
library and the scenario from the editor's API (:mod:`arena.web.api_editor`) and draws and edits
on its own, so the page needs no NiceGUI round trip to show its first drawing. Element ids start
with ``editor-`` (the browser tests use them).
"""

from __future__ import annotations

from nicegui import ui

from arena.web import pages

SCRIPT = "".join(f'<script src="/static/{name}"></script>'
                 for name in ("editor.js", "editor_panels.js", "editor_draw.js"))

STYLE = """
.editor{display:grid;grid-template-columns:300px 1fr 340px;gap:12px;width:100%;
  height:calc(100vh - 96px);font-size:13px;color:#1a202c}
.editor aside{overflow-y:auto;display:flex;flex-direction:column;gap:10px}
.editor section{background:#f7f8fa;border:1px solid #e2e8f0;border-radius:6px;padding:8px 10px}
.editor h3{font-weight:600;font-size:13px;text-transform:uppercase;letter-spacing:.04em;
  color:#4a5568;margin:0 0 6px}
.editor h4{font-weight:600;font-size:14px;line-height:1.3;letter-spacing:0;margin:2px 0 6px}
.editor label{display:grid;grid-template-columns:110px 1fr;align-items:center;gap:4px 6px;
  margin:3px 0}
.editor label small{grid-column:2;color:#718096;font-size:11px;line-height:1.2}
.editor input,.editor select{border:1px solid #cbd5e0;border-radius:4px;padding:2px 5px;
  background:#fff;min-width:0;width:100%}
.editor input[type=radio],.editor input[type=checkbox]{width:auto}
.editor details summary{cursor:pointer;color:#4a5568;margin:4px 0}
.editor-button{background:#2d3748;color:#fff;border-radius:4px;padding:3px 10px;margin:4px 4px 0 0;
  cursor:pointer}
.editor-button:hover{background:#4a5568}
.editor-danger{background:#c53030}
.editor-tools{display:grid;grid-template-columns:repeat(4,1fr);gap:4px}
.editor-tools button{border:1px solid #cbd5e0;border-radius:4px;padding:4px 2px;background:#fff;
  cursor:pointer}
.editor-tools button.editor-active{background:#2b6cb0;color:#fff;border-color:#2b6cb0}
.editor-main{display:flex;flex-direction:column;gap:4px;min-width:0}
#editor-canvas{flex:1;width:100%;min-height:0;border-radius:6px;background:#e8eaed;
  cursor:crosshair}
.editor-note{color:#4a5568;font-size:12px;margin:3px 0;overflow-wrap:anywhere}
.editor-bad{color:#c53030}
.editor-ok{color:#2f855a}
#editor-status{font-weight:700;font-size:15px}
.editor ul{margin:0;padding-left:16px}
.editor ul li{margin:3px 0;overflow-wrap:anywhere}
.editor code{background:#edf2f7;border-radius:3px;padding:0 3px;font-size:11px}
#editor-list{list-style:none;padding:0}
#editor-list li{cursor:pointer;padding:2px 4px;border-radius:3px}
#editor-list li:hover{background:#edf2f7}
#editor-list li.editor-active{background:#bee3f8}
"""

BODY = """
<div class="editor" id="editor-root">
<aside>
 <section><h3>Map</h3>
  <div class="editor-note" id="editor-map-label">loading…</div>
  <div>
   <label style="display:inline"><input type="radio" name="editor-source" value="world" checked>
    world</label>
   <label style="display:inline"><input type="radio" name="editor-source" value="generate">
    generate</label>
   <label style="display:inline"><input type="radio" name="editor-source" value="upload">
    upload</label>
   <label style="display:inline"><input type="radio" name="editor-source" value="saved">
    saved</label>
  </div>
  <div data-source="world">
   <label><span>world</span><select id="editor-world"></select></label>
   <label><span>start from</span><select id="editor-world-scenario"></select></label>
   <button class="editor-button" id="editor-load-world">load world</button>
  </div>
  <div data-source="generate">
   <label><span>generator</span><select id="editor-generator"></select></label>
   <label><span>seed</span><input id="editor-seed" type="number" min="0" value="0"></label>
   <div id="editor-gen-form"></div>
  </div>
  <div data-source="upload">
   <label><span>map.yaml</span><input id="editor-upload-yaml" type="file"
    accept=".yaml,.yml"></label>
   <label><span>image</span><input id="editor-upload-image" type="file"
    accept=".png,.pgm,.jpg,.jpeg,.bmp"></label>
   <div class="editor-note">ROS map_server map; at most 64 kB YAML, 8 MB and 4000 × 4000
    pixels image.</div>
  </div>
  <div data-source="saved">
   <label><span>saved map</span><select id="editor-saved-map"></select></label>
   <button class="editor-button" id="editor-load-map">load map</button>
  </div>
  <div data-source="generate upload">
   <label><span>save map as</span><input id="editor-map-name"
    placeholder="default: generator_seed"></label>
  </div>
  <div data-source="generate"><button class="editor-button" id="editor-generate">generate
   </button></div>
  <div data-source="upload"><button class="editor-button" id="editor-upload">upload</button>
  </div>
  <div class="editor-note" id="editor-message"></div>
 </section>
 <section><h3>Tools</h3>
  <div class="editor-tools">
   <button data-tool="select" id="editor-tool-select">select</button>
   <button data-tool="start" id="editor-tool-start">start</button>
   <button data-tool="goal" id="editor-tool-goal">goal</button>
   <button data-tool="pedestrian" id="editor-tool-pedestrian">person</button>
   <button data-tool="waypoint" id="editor-tool-waypoint">waypoint</button>
   <button data-tool="group" id="editor-tool-group">group</button>
   <button data-tool="obstacle" id="editor-tool-obstacle">obstacle</button>
   <button data-tool="zone" id="editor-tool-zone">zone</button>
  </div>
  <label><span>person type</span><select id="editor-ped-type"></select></label>
  <label><span>group size</span><input id="editor-group-size" type="number" min="2" max="8"
   value="3"></label>
  <label><span>select groups</span><input id="editor-group-select" type="checkbox"
   checked></label>
  <label><span>obstacle</span><select id="editor-obstacle-model"></select></label>
  <label><span>interactive</span><input id="editor-obstacle-interactive"
   type="checkbox"></label>
 </section>
 <section><h3>Selection</h3><div id="editor-props"></div></section>
</aside>
<div class="editor-main">
 <div class="editor-note" id="editor-hint"></div>
 <canvas id="editor-canvas"></canvas>
</div>
<aside>
 <section><h3>Validation</h3>
  <div id="editor-status">checking…</div>
  <ul id="editor-problems" class="editor-bad"></ul>
  <ul id="editor-warnings" class="editor-note"></ul>
 </section>
 <section><h3>Save</h3>
  <label><span>name</span><input id="editor-name" placeholder="my_scenario"></label>
  <button class="editor-button" id="editor-save">save scenario</button>
  <div class="editor-note" id="editor-save-result"></div>
  <label><span>open saved</span><select id="editor-open"></select></label>
  <button class="editor-button" id="editor-open-button">open</button>
 </section>
 <section><h3>Scenario</h3><ul id="editor-list"></ul></section>
</aside>
</div>
"""


@ui.page("/editor")
def editor(load: str = "") -> None:
    """The scenario editor (see the module doc); ``load`` names a saved scenario to open."""
    pages._header("scenario editor")
    ui.add_css(STYLE)
    ui.add_head_html(SCRIPT)
    ui.html(BODY, sanitize=False).classes("w-full")
    # the script waits for the last element of BODY (NiceGUI mounts it after this tag)
    ui.add_body_html("<script>arenaWhenEditorReady(() => arenaStartEditor("
                     f"{pages.js_literal({'load': load or None})}));</script>")
