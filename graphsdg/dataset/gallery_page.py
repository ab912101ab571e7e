"""The gallery page's own files: its stylesheet, its script and the HTML around them.

The page (``index.html``) is static: the statistics tables are written into it,
the frames' data (image files, boxes, classes) into ``gallery_data.js``, which
the page loads with a ``<script>`` tag so that it also works opened from disk
(``file://``, where browsers refuse ``fetch``). The script shows one page of
frames at a time (``#page=N`` in the address), each as its image with the
class masks, boxes and labels over it and its depth beside it; toolbar
switches toggle boxes, masks, labels and depth on every frame, each frame's
own switches on that frame, and the class chips hide and show classes (and,
with "only frames with these classes", frames).

Masks are greyscale PNGs holding class ids; one SVG filter colours them
(``feComponentTransfer`` tables: class id -> class colour, and -> 0/1 for
"class shown"), so hiding a class rewrites one table instead of redrawing
thousands of images, and the mask images need no canvas (which ``file://``
images would taint). Masks are scaled with ``image-rendering: pixelated`` so
the filter sees exact ids.
"""
from __future__ import annotations

CSS = """
*{box-sizing:border-box}
html,body{margin:0;padding:0}
body{font:14px/1.4 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;color:#1d2330;background:#f4f5f7}
header{padding:14px 20px 6px}
h1{font-size:20px;margin:0 0 4px;overflow-wrap:anywhere}
h2{font-size:16px;margin:18px 0 8px}
.sub{color:#5b6475;overflow-wrap:anywhere}
main{padding:0 20px 40px}
.stats{display:flex;flex-wrap:wrap;gap:16px;align-items:flex-start}
.stats>div{min-width:0;max-width:100%}
.table-wrap{max-width:100%;overflow-x:auto;background:#fff;border:1px solid #dde1e8;border-radius:6px}
table{border-collapse:collapse;font-variant-numeric:tabular-nums}
th,td{padding:4px 10px;text-align:right;border-bottom:1px solid #eceef2;white-space:nowrap}
th{background:#f8f9fb;font-weight:600}
th:first-child,td:first-child{text-align:left}
#per-class td:first-child{white-space:normal;overflow-wrap:anywhere;min-width:10em}
.swatch{display:inline-block;width:11px;height:11px;border-radius:2px;margin-right:6px;vertical-align:-1px}
details{max-width:100%;overflow-wrap:anywhere}
.toolbar{position:sticky;top:0;z-index:5;background:#fff;border-bottom:1px solid #dde1e8;padding:8px 20px;
 display:flex;flex-wrap:wrap;gap:6px 16px;align-items:center}
.toolbar .group{display:flex;flex-wrap:wrap;gap:4px 10px;align-items:center;min-width:0;max-width:100%}
.toolbar label{white-space:nowrap;cursor:pointer}
.toolbar label.chip{border:1px solid #ccd2dc;border-radius:12px;padding:1px 8px;background:#fff;white-space:normal;
 overflow-wrap:anywhere;max-width:100%}
.chip.off{opacity:.45}
.pager button{padding:2px 10px}
.grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(400px,1fr));gap:14px;margin-top:14px}
.frame{background:#fff;border:1px solid #dde1e8;border-radius:6px;padding:8px;min-width:0}
.frame h3{font-size:13px;margin:0 0 6px;display:flex;flex-wrap:wrap;gap:4px 10px;align-items:baseline}
.frame h3 .name{font-weight:600;overflow-wrap:anywhere;min-width:0}
.frame h3 .meta{color:#5b6475;font-weight:400}
.frame h3 .own{margin-left:auto;font-weight:400;display:flex;gap:8px}
.views{display:grid;grid-template-columns:1fr;gap:6px}
.frame.with-depth .views{grid-template-columns:1fr 1fr}
.stack{position:relative;line-height:0;min-width:0;overflow:hidden}
.stack img{display:block;width:100%;height:auto}
.stack .mask{position:absolute;inset:0;height:100%;image-rendering:pixelated;filter:url(#classmask);opacity:.5}
.box{position:absolute;border:2px solid;pointer-events:none}
.label{position:absolute;transform:translateY(-100%);font:11px/1.3 system-ui,sans-serif;color:#fff;padding:0 3px;
 white-space:nowrap;pointer-events:none;max-width:100%;overflow:hidden;text-overflow:ellipsis}
.label.inside{transform:none}
.depth figcaption{line-height:1.3;font-size:12px;color:#5b6475;margin-top:3px}
.depth{margin:0;min-width:0}
.depth img{display:block;width:100%;height:auto}
.hide-boxes .box,.hide-labels .label,.hide-masks .mask{display:none}
.frame.hide-depth .views{grid-template-columns:1fr}
.frame.hide-depth .depth{display:none}
.empty{color:#5b6475;padding:20px}
"""

SCRIPT = r"""
(function () {
  "use strict";
  const G = window.GALLERY;
  const byId = new Map(G.classes.map(c => [c.id, c]));
  const state = {page: 0, all: {boxes: true, masks: true, labels: true, depth: true}, own: new Map(),
                 shown: new Set(G.classes.map(c => c.id)), onlyWith: false};
  const $ = sel => document.querySelector(sel);
  const el = (tag, attrs, kids) => {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === "text") e.textContent = v; else if (k === "style") e.style.cssText = v; else e.setAttribute(k, v);
    }
    for (const kid of kids || []) e.appendChild(kid);
    return e;
  };

  function visibleFrames() {
    if (!state.onlyWith) return G.frames;
    return G.frames.filter(f => f.boxes.some(b => state.shown.has(b[0])) ||
                                (f.classes || []).some(c => state.shown.has(c)));
  }
  function pages() { return Math.max(1, Math.ceil(visibleFrames().length / G.pageSize)); }

  function updateClassStyles() {
    const hidden = G.classes.filter(c => !state.shown.has(c.id)).map(c => ".k" + c.id).join(",");
    $("#class-filter-style").textContent = hidden ? hidden + "{display:none}" : "";
    const on = new Array(256).fill(0);
    for (const id of state.shown) if (id < 256) on[id] = 1;
    $("#mask-on").setAttribute("tableValues", on.join(" "));
    for (const chip of document.querySelectorAll(".chip[data-class]"))
      chip.classList.toggle("off", !state.shown.has(+chip.dataset.class));
  }

  function switches(frame) { return Object.assign({}, state.all, state.own.get(frame.name) || {}); }

  function applySwitches(card, frame) {
    const s = switches(frame);
    for (const k of ["boxes", "masks", "labels", "depth"]) {
      card.classList.toggle("hide-" + k, !s[k]);
      const box = card.querySelector("input[data-own='" + k + "']");
      if (box) box.checked = s[k];
    }
  }

  function card(frame) {
    const c = el("article", {class: "frame" + (frame.depth ? " with-depth" : ""), "data-name": frame.name});
    const own = el("span", {class: "own"});
    for (const k of ["boxes", "masks", "labels"].concat(frame.depth ? ["depth"] : [])) {
      const input = el("input", {type: "checkbox", "data-own": k});
      input.addEventListener("change", () => {
        const o = Object.assign({}, state.own.get(frame.name) || {});
        o[k] = input.checked;
        state.own.set(frame.name, o);
        applySwitches(c, frame);
      });
      own.appendChild(el("label", {}, [input, document.createTextNode(" " + k)]));
    }
    c.appendChild(el("h3", {}, [el("span", {class: "name", text: frame.name}),
                               el("span", {class: "meta", text: frame.boxes.length + " boxes"}), own]));
    const stack = el("div", {class: "stack"}, [el("img", {class: "rgb", src: frame.rgb, alt: frame.name,
                                                          width: frame.w, height: frame.h})]);
    if (frame.mask) stack.appendChild(el("img", {class: "mask", src: frame.mask, alt: ""}));
    for (const [k, x0, y0, x1, y1] of frame.boxes) {
      const cls = byId.get(k) || {name: "?", colour: "#ff00ff"};
      const pos = "left:" + (100 * x0 / frame.w) + "%;top:" + (100 * y0 / frame.h) + "%;";
      stack.appendChild(el("div", {class: "box k" + k, style: pos + "width:" + (100 * (x1 - x0 + 1) / frame.w) +
                                   "%;height:" + (100 * (y1 - y0 + 1) / frame.h) + "%;border-color:" + cls.colour}));
      // a label sits above its box, or inside it where the box touches the image's top edge
      stack.appendChild(el("span", {class: "label k" + k + (y0 < 0.06 * frame.h ? " inside" : ""), text: cls.name,
                                    style: pos + "background:" + cls.colour}));
    }
    const views = el("div", {class: "views"}, [stack]);
    if (frame.depth) {
      const range = frame.depthRange ? frame.depthRange[0].toFixed(2) + " to " + frame.depthRange[1].toFixed(2) + " m"
                                      : "no depth";
      views.appendChild(el("figure", {class: "depth"}, [el("img", {src: frame.depth, alt: "depth of " + frame.name,
                                                                  width: frame.w, height: frame.h}),
                                                        el("figcaption", {text: "depth " + range})]));
    }
    c.appendChild(views);
    applySwitches(c, frame);
    return c;
  }

  function render() {
    const list = visibleFrames();
    state.page = Math.min(Math.max(0, state.page), pages() - 1);
    const grid = $("#frames");
    grid.textContent = "";
    const slice = list.slice(state.page * G.pageSize, (state.page + 1) * G.pageSize);
    for (const f of slice) grid.appendChild(card(f));
    if (!slice.length) grid.appendChild(el("p", {class: "empty", text: "no frame shows the selected classes"}));
    $("#page-info").textContent = "page " + (state.page + 1) + " of " + pages() + " (" + list.length + " frames)";
    $("#prev").disabled = state.page === 0;
    $("#next").disabled = state.page >= pages() - 1;
    const wanted = "#page=" + (state.page + 1);
    if (location.hash !== wanted) history.replaceState(null, "", wanted);
  }

  function build() {
    const chips = $("#classes");
    for (const c of G.classes) {
      const input = el("input", {type: "checkbox", checked: ""});
      input.addEventListener("change", () => {
        if (input.checked) state.shown.add(c.id); else state.shown.delete(c.id);
        updateClassStyles();
        if (state.onlyWith) render();
      });
      chips.appendChild(el("label", {class: "chip", "data-class": c.id},
                           [input, el("span", {class: "swatch", style: "background:" + c.colour}),
                            document.createTextNode(c.name)]));
    }
    for (const input of document.querySelectorAll("input[data-all]")) {
      input.addEventListener("change", () => {
        state.all[input.dataset.all] = input.checked;
        for (const o of state.own.values()) delete o[input.dataset.all];
        for (const c of document.querySelectorAll(".frame"))
          applySwitches(c, G.frames.find(f => f.name === c.dataset.name));
      });
    }
    $("#only-with").addEventListener("change", e => { state.onlyWith = e.target.checked; state.page = 0; render(); });
    const turn = step => () => { state.page += step; render(); window.scrollTo(0, $("#frames").offsetTop - 60); };
    $("#prev").addEventListener("click", turn(-1));
    $("#next").addEventListener("click", turn(1));
    const m = /page=(\d+)/.exec(location.hash);
    state.page = m ? +m[1] - 1 : 0;
    window.addEventListener("hashchange", () => {
      const h = /page=(\d+)/.exec(location.hash);
      if (h && +h[1] - 1 !== state.page) { state.page = +h[1] - 1; render(); }
    });
    updateClassStyles();
    render();
  }
  build();
})();
"""

PAGE = """<!doctype html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width,initial-scale=1">
<title>{title}</title><style>{css}</style><style id="class-filter-style"></style></head>
<body>
<svg width="0" height="0" style="position:absolute" aria-hidden="true"><defs>
<filter id="classmask" color-interpolation-filters="sRGB" x="0" y="0" width="100%" height="100%">
<feComponentTransfer in="SourceGraphic" result="colour">
<feFuncR type="discrete" tableValues="{red}"/><feFuncG type="discrete" tableValues="{green}"/>
<feFuncB type="discrete" tableValues="{blue}"/></feComponentTransfer>
<feComponentTransfer in="SourceGraphic" result="on"><feFuncR id="mask-on" type="discrete" tableValues="{on}"/>
</feComponentTransfer>
<feColorMatrix in="on" type="matrix" values="0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 1 0 0 0 0" result="shown"/>
<feComposite in="colour" in2="shown" operator="in"/>
</filter></defs></svg>
<header><h1>{heading}</h1><div class="sub">{subtitle}</div></header>
<main>
<section class="stats">{tables}</section>
{empty}
</main>
<nav class="toolbar" aria-label="what is drawn">
<span class="group"><b>draw</b>
<label><input type="checkbox" data-all="boxes" checked> boxes</label>
<label><input type="checkbox" data-all="masks" checked> masks</label>
<label><input type="checkbox" data-all="labels" checked> labels</label>
<label><input type="checkbox" data-all="depth" checked> depth</label></span>
<span class="group" id="classes"><b>classes</b></span>
<label><input type="checkbox" id="only-with"> only frames with these classes</label>
<span class="group pager"><button id="prev" type="button">&#8592; prev</button><span id="page-info"></span>
<button id="next" type="button">next &#8594;</button></span>
</nav>
<main><section class="grid" id="frames"></section></main>
<script src="gallery_data.js"></script>
<script>{script}</script>
</body></html>
"""
