// The page of the live view (lib/murdoch/view/).  It reads the run's
// trace -- a line describing the room, then one snapshot per line -- from
// /trace, then, when the run is live, each new snapshot from /events.
// It draws one snapshot at a time: the one the time slider points at,
// which follows the newest while "follow" is ticked.
"use strict";

const SVG = "http://www.w3.org/2000/svg";
// sim/trace.c draws the simulator's SVG with this same list.
const COLOURS = ["#1565c0", "#c62828", "#2e7d32", "#6a1b9a", "#ef6c00",
                 "#00838f", "#4e342e", "#ad1457", "#558b2f", "#283593"];

let header = null;       // the room
let states = [];         // the snapshots, in order
let live = false;
let selected = null;     // the robot whose sonar is drawn
let shown = -1;          // the index of the snapshot drawn
let playing = null;      // the timer of a replay being played

const byId = (id) => document.getElementById(id);

function el(name, attrs, parent, ns) {
  const e = ns ? document.createElementNS(SVG, name) : document.createElement(name);
  for (const k in attrs || {}) e.setAttribute(k, attrs[k]);
  if (parent) parent.appendChild(e);
  return e;
}

function textEl(name, text, attrs, parent, ns) {
  const e = el(name, attrs, parent, ns);
  e.textContent = text;
  return e;
}

// Robots and workstations keep the colour of their place in the lab file.
function colour(name) {
  const i = header.aspaces.findIndex((a) => a.name === name);
  return COLOURS[(i < 0 ? 0 : i) % COLOURS.length];
}

function isRobot(name) {
  const a = header.aspaces.find((a) => a.name === name);
  return a && a.robot;
}

const rad = (deg) => deg * Math.PI / 180;
// World millimetres, y up, to the SVG's y down.
const X = (x) => x;
const Y = (y) => -y;

// The rectangle that holds the walls, the boxes and every pose seen.
function bounds() {
  const xs = [], ys = [];
  for (const w of header.walls) { xs.push(w[0], w[2]); ys.push(w[1], w[3]); }
  for (const b of header.boxes) { xs.push(b[0]); ys.push(b[1]); }
  for (const s of states.slice(0, 1).concat(states.slice(-1)))
    for (const a of s.aspaces) if (a.pose) { xs.push(a.pose[0]); ys.push(a.pose[1]); }
  if (!xs.length) { xs.push(-1000, 1000); ys.push(-1000, 1000); }
  const m = 400;
  return { x0: Math.min(...xs) - m, x1: Math.max(...xs) + m,
           y0: Math.min(...ys) - m, y1: Math.max(...ys) + m };
}

function boxPolygon(b) {
  const [x, y, w, d, h] = b, c = Math.cos(rad(h)), s = Math.sin(rad(h));
  return [[-w / 2, -d / 2], [w / 2, -d / 2], [w / 2, d / 2], [-w / 2, d / 2]]
    .map(([u, v]) => `${X(x + u * c - v * s)},${Y(y + u * s + v * c)}`).join(" ");
}

// The sonar ring of a robot at pose: sonar i faces heading + 22.5 i, a
// cone of 25 degrees out to its range.
function drawSonar(g, pose, ranges, c) {
  ranges.forEach((r, i) => {
    const a = rad(pose[2] + 22.5 * i), half = rad(12.5);
    const p = (t) => `${X(pose[0] + r * Math.cos(t))},${Y(pose[1] + r * Math.sin(t))}`;
    el("polygon", { points: `${X(pose[0])},${Y(pose[1])} ${p(a - half)} ${p(a + half)}`,
                    fill: c, "fill-opacity": 0.07, stroke: c, "stroke-opacity": 0.25,
                    "stroke-width": 6, class: "sonar" }, g, true);
    // The echo: where the sonar heard something.
    el("circle", { cx: X(pose[0] + r * Math.cos(a)), cy: Y(pose[1] + r * Math.sin(a)), r: 45,
                   fill: c, "fill-opacity": 0.8, class: "echo" }, g, true);
  });
}

function drawRoom(k) {
  const svg = byId("room");
  while (svg.firstChild) svg.removeChild(svg.firstChild);
  const b = bounds();
  svg.setAttribute("viewBox", `${b.x0} ${-b.y1} ${b.x1 - b.x0} ${b.y1 - b.y0}`);
  const state = states[k];
  // A grid of one metre.
  const grid = el("g", { stroke: "#eee", "stroke-width": 10 }, svg, true);
  for (let x = Math.ceil(b.x0 / 1000) * 1000; x < b.x1; x += 1000)
    el("line", { x1: x, y1: -b.y1, x2: x, y2: -b.y0 }, grid, true);
  for (let y = Math.ceil(b.y0 / 1000) * 1000; y < b.y1; y += 1000)
    el("line", { x1: b.x0, y1: -y, x2: b.x1, y2: -y }, grid, true);
  for (const w of header.walls)
    el("line", { x1: X(w[0]), y1: Y(w[1]), x2: X(w[2]), y2: Y(w[3]), stroke: "#37474f",
                 "stroke-width": w[4], "stroke-linecap": "square", class: "wall" }, svg, true);
  const boxes = state ? state.boxes : header.boxes;
  boxes.forEach((bx, i) => {
    el("polygon", { points: boxPolygon(bx), fill: "#d7ccc8", stroke: "#795548",
                    "stroke-width": 15, class: "box" }, svg, true);
    textEl("text", `box ${i}`, { x: X(bx[0]), y: Y(bx[1]), "text-anchor": "middle",
                                 "dominant-baseline": "middle", "font-size": 120,
                                 fill: "#5d4037" }, svg, true);
  });
  if (!state) return;
  // Paths: every pose so far.
  for (const a of state.aspaces) {
    if (!isRobot(a.name)) continue;
    const pts = [];
    for (let i = 0; i <= k; i++) {
      const s = states[i].aspaces.find((x) => x.name === a.name);
      if (s && s.pose) pts.push(`${X(s.pose[0])},${Y(s.pose[1])}`);
    }
    el("polyline", { "data-name": a.name, points: pts.join(" "), fill: "none", stroke: colour(a.name),
                     "stroke-width": 20, "stroke-dasharray": "60 40", "stroke-opacity": 0.7,
                     class: "path" }, svg, true);
  }
  const sel = state.aspaces.find((a) => a.name === selected);
  if (sel && sel.sonar) drawSonar(el("g", {}, svg, true), sel["sonar-at"] || sel.pose, sel.sonar, colour(sel.name));
  for (const a of state.aspaces) {
    if (!a.pose) continue;
    const [x, y, h] = a.pose, c = colour(a.name), r = header.radius;
    const g = el("g", { class: isRobot(a.name) ? "robot" : "workstation",
                        "data-name": a.name }, svg, true);
    if (a.goal)
      el("path", { d: `M${X(a.goal[0]) - 100},${Y(a.goal[1]) - 100} l200,200 m0,-200 l-200,200`,
                   stroke: c, "stroke-width": 30, class: "goal" }, g, true);
    if (isRobot(a.name)) {
      const holds = a.held && a.held.length > 0;
      el("circle", { cx: X(x), cy: Y(y), r: r, fill: c, "fill-opacity": a.away ? 0.15 : 0.55,
                     stroke: holds ? "#ffb300" : c, "stroke-width": holds ? 50 : 15 }, g, true);
      el("line", { x1: X(x), y1: Y(y), x2: X(x + 1.6 * r * Math.cos(rad(h))),
                   y2: Y(y + 1.6 * r * Math.sin(rad(h))), stroke: "#000", "stroke-width": 25,
                   class: "heading" }, g, true);
      g.addEventListener("click", () => { selected = a.name; show(shown, true); });
      g.style.cursor = "pointer";
    } else {
      el("rect", { x: X(x) - 150, y: Y(y) - 150, width: 300, height: 300, fill: c,
                   "fill-opacity": 0.35, stroke: c, "stroke-width": 15 }, g, true);
    }
    textEl("text", a.name, { x: X(x), y: Y(y) - r - 60, "text-anchor": "middle",
                             class: "name", fill: c }, g, true);
  }
}

function fmt(n, digits) { return n === null || n === undefined ? "" : n.toFixed(digits || 0); }

function since(t) { return `${fmt(t, 1)} s`; }

function drawAspaces(state) {
  const body = byId("aspaces").tBodies[0];
  while (body.firstChild) body.removeChild(body.firstChild);
  for (const a of state.aspaces) {
    const tr = el("tr", { "data-name": a.name, class: (isRobot(a.name) ? "robot" : "") +
                          (a.name === selected ? " selected" : "") }, body);
    const name = textEl("td", a.name, {}, tr);
    name.style.color = colour(a.name);
    name.style.fontWeight = "bold";
    if (a.away) {
      textEl("td", `away: ${a.why}`, { class: "away", colspan: 4 }, tr);
    } else {
      textEl("td", `up ${Math.round(state.clock - a.since)} s`, {}, tr);
      textEl("td", a.pose ? `${fmt(a.pose[0])} ${fmt(a.pose[1])} ${fmt(a.pose[2])}` : "", {}, tr);
      textEl("td", a.battery === null ? "" : `${fmt(a.battery, 1)} V`, {}, tr);
      textEl("td", a.held.map((h) => `${h[0]} for ${h[1]}`).join(", "), {}, tr);
    }
    if (isRobot(a.name))
      tr.addEventListener("click", () => { selected = a.name; show(shown, true); });
  }
}

function drawTasks(state) {
  const box = byId("tasks");
  while (box.firstChild) box.removeChild(box.firstChild);
  if (!state.tasks.length) {
    textEl("p", "No task seen yet.", { class: "hint" }, box);
    return;
  }
  for (const t of state.tasks) {
    const div = el("div", { class: "task", "data-task": t.name }, box);
    const h = el("h3", {}, div);
    textEl("span", t.name, { class: "task-name" }, h);
    textEl("span", ` posed by ${t.poser || "?"}`, {}, h);
    if (t.coordinator) {
      textEl("span", `, coordinated by ${t.coordinator}` +
             (t.standby ? ` (standby ${t.standby})` : " (no standby)"),
             { class: "keepers" }, h);
    }
    textEl("span", ": ", {}, h);
    textEl("span", t.state, { class: `state-${t.state.replace(/ /g, "-")}` }, h);
    const table = el("table", {}, div);
    const head = el("tr", {}, table);
    for (const c of ["component", "won by", "subjects", "from", "to", "note"]) textEl("th", c, {}, head);
    for (const c of t.components) {
      const tr = el("tr", { class: "component" }, table);
      textEl("td", c.index === null ? "-" : String(c.index), {}, tr);
      const who = textEl("td", c.robot, { class: "winner" }, tr);
      who.style.color = colour(c.robot);
      textEl("td", c.subjects.join(" "), {}, tr);
      textEl("td", since(c.since), {}, tr);
      textEl("td", c.until === null ? "running" : since(c.until), {}, tr);
      const notes = [];
      if (c.from) notes.push(`reassigned from ${c.from}`);
      if (c.end && c.end !== "done") notes.push(c.end);
      textEl("td", notes.join("; "), {}, tr);
    }
  }
}

function drawClock(state) {
  const wall = new Date(state.clock * 1000);
  byId("clock").textContent =
    `t = ${fmt(state.t, 1)} s   ${wall.toISOString().substring(11, 19)} UTC`;
}

function drawLegend() {
  const ul = byId("legend");
  const item = (draw, label) => {
    const li = el("li", {}, ul);
    const s = el("svg", { width: 28, height: 16, viewBox: "0 0 28 16" }, li, true);
    draw(s);
    li.appendChild(document.createTextNode(label));
  };
  item((s) => el("circle", { cx: 14, cy: 8, r: 6, fill: COLOURS[0], "fill-opacity": 0.55,
                             stroke: COLOURS[0] }, s, true), "robot, with its heading");
  item((s) => el("circle", { cx: 14, cy: 8, r: 6, fill: COLOURS[0], "fill-opacity": 0.55,
                             stroke: "#ffb300", "stroke-width": 3 }, s, true), "robot holding subjects for a task");
  item((s) => el("rect", { x: 8, y: 2, width: 12, height: 12, fill: COLOURS[2],
                           "fill-opacity": 0.35, stroke: COLOURS[2] }, s, true), "workstation");
  item((s) => el("line", { x1: 2, y1: 8, x2: 26, y2: 8, stroke: COLOURS[0], "stroke-width": 2,
                           "stroke-dasharray": "5 3" }, s, true), "path so far");
  item((s) => el("polygon", { points: "2,8 26,2 26,14", fill: COLOURS[0], "fill-opacity": 0.15,
                              stroke: COLOURS[0] }, s, true), "the chosen robot's last sonar reading, from where it was read");
  item((s) => el("line", { x1: 2, y1: 8, x2: 26, y2: 8, stroke: "#37474f", "stroke-width": 4 }, s, true), "wall");
  item((s) => el("rect", { x: 6, y: 2, width: 16, height: 12, fill: "#d7ccc8", stroke: "#795548" }, s, true), "box");
  item((s) => el("path", { d: "M9,3 l10,10 m0,-10 l-10,10", stroke: COLOURS[0], "stroke-width": 2 }, s, true), "goto target, when known");
}

// Draws snapshot k; again only when asked to.
function show(k, again) {
  if (k < 0 || k >= states.length || (k === shown && !again)) return;
  shown = k;
  const slider = byId("time");
  slider.max = String(states.length - 1);
  slider.value = String(k);
  drawRoom(k);
  drawAspaces(states[k]);
  drawTasks(states[k]);
  drawClock(states[k]);
}

function add(state) {
  states.push(state);
  byId("time").max = String(states.length - 1);
  if (byId("follow").checked) show(states.length - 1);
}

function play() {
  if (playing) { clearInterval(playing); playing = null; return; }
  byId("follow").checked = false;
  let k = 0;
  playing = setInterval(() => {
    show(k++);
    if (k >= states.length) { clearInterval(playing); playing = null; }
  }, 100);
}

// The whole lines of the trace so far: the room, then the snapshots.
async function traceLines() {
  const text = await (await fetch("/trace")).text();
  // Only whole lines: the last may be being written.
  return text.split("\n").slice(0, -1).filter((l) => l.length);
}

function parseStates(lines) {
  const out = [];
  for (const l of lines) {
    try { out.push(JSON.parse(l)); } catch (e) { break; }
  }
  return out;
}

// A page that fell behind what the server keeps reads the trace again.
let resyncing = false;
async function resync() {
  if (resyncing) return;
  resyncing = true;
  states = parseStates((await traceLines()).slice(1));
  resyncing = false;
  if (byId("follow").checked) show(states.length - 1, true);
}

async function start() {
  const info = await (await fetch("/info")).json();
  live = info.live;
  byId("mode").textContent = live ? "live" : `replay of ${info.trace}`;
  const lines = await traceLines();
  header = JSON.parse(lines[0]);
  byId("lab-name").textContent = `lab ${header.lab}`;
  document.title = `Murdoch: lab ${header.lab}`;
  const robot = header.aspaces.find((a) => a.robot);
  selected = robot ? robot.name : null;
  drawLegend();
  states = parseStates(lines.slice(1));
  byId("time").addEventListener("input", (e) => {
    byId("follow").checked = false;
    show(Number(e.target.value));
  });
  byId("follow").addEventListener("change", (e) => { if (e.target.checked) show(states.length - 1); });
  byId("play").addEventListener("click", play);
  if (states.length) show(states.length - 1); else drawRoom(-1);
  if (live) follow();
}

// New snapshots, as server-sent events; or, with ?poll=MS in the page's
// address, by asking /events for what is new every MS milliseconds (for
// a headless browser with a virtual-time budget, which waits for every
// open connection to end).
function follow() {
  const poll = new URLSearchParams(location.search).get("poll");
  if (!poll) {
    const events = new EventSource(`/events?from=${states.length}`);
    // Each event's id is its snapshot's place in the trace.
    events.onmessage = (e) => {
      const id = Number(e.lastEventId);
      if (id === states.length) add(JSON.parse(e.data));
      else if (id > states.length) resync();
    };
    return;
  }
  const next = async () => {
    const text = await (await fetch(`/events?from=${states.length}&once=1`)).text();
    for (const event of text.split("\n\n")) {
      const id = /^id: (\d+)$/m.exec(event), data = /^data: (.*)$/m.exec(event);
      if (id && data && Number(id[1]) === states.length) add(JSON.parse(data[1]));
      else if (id && Number(id[1]) > states.length) { await resync(); break; }
    }
    setTimeout(next, Number(poll));
  };
  next();
}

start();
