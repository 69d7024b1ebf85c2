// msdlab's live view and replay player: a mass-spring body drawn on a canvas.
//
// The page draws at its own frame rate (requestAnimationFrame) and never waits for
// Python. The kernel sends one message per state (positions, and every few states
// the energies and the status line) at the page's frame rate, which the page reports;
// the page queues the states and shows one a frame, so states that arrive together
// (the network bunches small messages) are each shown, not only the last. 2-D bodies are drawn as they are;
// 3-D ones through an orbit camera (orthographic: left-drag on empty space or
// right-drag turns, the wheel zooms). Springs are drawn by strain in the colour and the
// line of their level that the scene brings (64 levels; thin dashed squeezed, plain near
// rest, thick stretched: msdlab/viz/strain_style.py), with a key under the body.
// Everything works by keyboard too (the body's canvas: the focus among particles, the hand,
// pins; the view: run, step, reset, the instruments), and the view speaks: two polite live
// regions say what the keys did and, every 2 s at most, what the body does (words from
// Python, msdlab/viz/words.py); a tone can follow the kinetic energy's share.

const LEVELS = 64;
const PICK_RADIUS = 25; // px: how near the mouse a particle must be to be taken
const HISTORY = 600; // points of the energy plot
const HELD_COLOUR = "#e8a317"; // the ring round the particle in hand
// the ledger's entries of energy put in (booked negative), shown as the work done
const PUT_IN = { hand: "hand's work", driven: "driven particles' work" };
/** The colour of each energy bar: one of its own for every energy in the body, every
 * mechanism that takes energy out and the work put in (red for a mechanism not listed);
 * the hand's work has the colour of the ring drawn round the particle in hand. */
const BAR_COLOURS = { kinetic: "#2ca02c", elastic: "#1f77b4", gravitational: "#9467bd",
  "other potential": "#bcbd22", dashpot: "#8c564b", integrator: "#7f7f7f", ground: "#e377c2",
  viscous: "#17becf", drag: "#d62728", walls: "#393b79", "hand's work": HELD_COLOUR,
  "driven particles' work": "#ff7f0e", total: "#333" };
const DENSE = 3000; // springs from which lines are written as pixels (`Pixels`)
const SURFACE_ONLY = 30000; // springs from which a 3-D body is drawn by its surface
const QUEUED = 6; // states kept waiting at most: older ones are dropped (6 frames late at most)
const PICTURE_TIMES = 1200; // times of the last new pictures kept in a view's stats
const REPORT_EVERY = 1000; // ms between two reports of the page's frame rate to the kernel
// ms over which the hand's moves go to the kernel together, in one message: each message
// is a request the kernel's main thread answers (and two status messages back), which
// takes the interpreter from the stepping thread; with a message a move (60 a second) the
// page showed 11 new pictures a second while dragged on a loaded machine, 24 with the moves
// of 50 ms together, 34 with those of 100 ms (benchmarks/live_view.py). The kernel plays
// the moves back at their pace whenever they come; the page draws the held particle at
// the hand at once.
const MOVES_EVERY = 100;
// The keyboard's hand (WCAG 2.1.1): a key press moves the hand by a step, over `GLIDE` ms at
// most (a move in one engine step would fling the particle); the moves of an arrow key held
// down join into one path, as a pointer's do.
const GLIDE = 50;
const SAY_EVERY = 2000; // ms: the body's line is said at most this often, and only when new
const TABLE_EVERY = 500; // ms between two updates of the energy bars' table
let views = 0; // views on the page: each names its own help text's id

/** A typed array of `Type` over a DataView, ArrayBuffer or typed array. */
function typed(data, Type) {
  if (data instanceof Type) return data;
  const buffer = data.buffer ?? data;
  const offset = data.byteOffset ?? 0;
  const length = (data.byteLength ?? buffer.byteLength) / Type.BYTES_PER_ELEMENT;
  return new Type(buffer, offset, length);
}

/** An array of `Type` from deflated bytes in base64 (the replay page's arrays). */
async function inflate(text, Type) {
  const bytes = Uint8Array.from(atob(text), (c) => c.charCodeAt(0));
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate"));
  return new Type(await new Response(stream).arrayBuffer());
}

/** Positions (float32) from 16-bit steps above `low` (per axis), each frame of
 * `frameSize` numbers stored as its change from the frame before (mod 2^16). */
function positionsOf(changes, frameSize, low, step) {
  const d = low.length, out = new Float32Array(changes.length);
  const level = new Uint16Array(frameSize);
  for (let i = 0; i < changes.length; i++) {
    const k = i % frameSize;
    level[k] += changes[i]; // wraps as the differences did
    out[i] = low[k % d] + level[k] * step[k % d];
  }
  return out;
}

function element(tag, attributes = {}, parent = null) {
  const node = Object.assign(document.createElement(tag), attributes);
  if (parent) parent.appendChild(node);
  return node;
}

/** Text a screen reader reads but the eye does not see, and a ring round the focus. */
const STYLE = `.msdlab-hidden { position: absolute; width: 1px; height: 1px; overflow: hidden;
  clip: rect(0 0 0 0); clip-path: inset(50%); white-space: nowrap; }
.msdlab-live :focus-visible, .msdlab-live:focus-visible { outline: 3px solid #1a5fb4;
  outline-offset: 2px; }
.msdlab-live .msdlab-canvas:focus-visible { outline-offset: -3px; }
.msdlab-full { margin: 4px 0; padding: 4px 6px; border-left: 3px solid #1a5fb4;
  max-width: 640px; }`;

function addStyle() {
  if (document.getElementById("msdlab-style")) return;
  element("style", { id: "msdlab-style", textContent: STYLE }, document.head);
}

/** A polite live region: `say(text)` is read out at most every `every` ms, the newest
 * text then, and only if it differs from the last said (at once with `every` = 0). */
class Announcer {
  constructor(parent, every, name) {
    this.node = element("div", { className: `${name} msdlab-hidden` }, parent);
    this.node.setAttribute("aria-live", "polite");
    this.every = every;
    this.said = "";
    this.at = -Infinity;
    this.waiting = null;
  }

  say(text) {
    this.next = text;
    if (this.waiting !== null) return;
    const wait = this.at + this.every - performance.now();
    if (wait <= 0) this.flush();
    else this.waiting = setTimeout(() => this.flush(), wait);
  }

  flush() {
    this.waiting = null;
    if (this.next === this.said) return;
    this.node.textContent = this.said = this.next;
    this.at = performance.now();
  }

  stop() {
    clearTimeout(this.waiting);
  }
}

/** A tone whose pitch follows the share of the energy in the body that is kinetic: 220 Hz
 * at rest, 880 Hz all in motion (two octaves). Off until `toggle()` (a key press or a click
 * starts the browser's audio). */
class Tone {
  constructor() {
    this.on = false;
    this.frequency = 220;
  }

  toggle() {
    this.on = !this.on;
    if (!this.audio && this.on) this.start();
    this.gain?.gain.setTargetAtTime(this.on ? 0.05 : 0, this.audio.currentTime, 0.05);
    return this.on;
  }

  start() {
    this.audio = new AudioContext();
    this.oscillator = this.audio.createOscillator();
    this.gain = this.audio.createGain();
    this.gain.gain.value = 0;
    this.oscillator.connect(this.gain).connect(this.audio.destination);
    this.oscillator.start();
  }

  follow(energy) {
    const inBody = Math.abs(energy.kinetic) + Math.abs(energy.elastic)
      + Math.abs(energy.gravitational);
    this.frequency = 220 * 4 ** (inBody > 0 ? Math.abs(energy.kinetic) / inBody : 0);
    if (this.on) this.oscillator.frequency.setTargetAtTime(this.frequency, this.audio.currentTime, 0.1);
  }

  stop() {
    this.audio?.close();
  }
}

/** `value` to a hundredth of `scale` (a view's span), as msdlab/viz/words.py says it. */
function number(value, scale) {
  const places = Math.max(0, -Math.floor(Math.log10(scale / 100)));
  const text = value.toFixed(places);
  return Number(text) === 0 ? "0" : text;
}

/** Where particle `p` of `x` is, in words: "x 0.12, y -0.40 m". */
function placeOf(x, p, scene) {
  const d = scene.dim, axes = "xyz";
  const parts = Array.from({ length: d }, (_, k) => `${axes[k]} ${number(x[d * p + k], scene.span)}`);
  return `${parts.join(", ")} ${scene.length_unit ?? ""}`.trim();
}

/** Where the camera looks from: azimuth about the up axis, elevation, zoom. */
class Camera {
  constructor(scene, width, height) {
    this.dim = scene.dim;
    this.up = scene.up; // index of the vertical axis
    this.centre = scene.centre;
    this.span = scene.span; // the largest extent to show (length units)
    this.azimuth = (scene.view[0] * Math.PI) / 180;
    this.elevation = (scene.view[1] * Math.PI) / 180;
    this.zoom = 1;
    this.resize(width, height);
  }

  resize(width, height) {
    this.width = width;
    this.height = height;
  }

  get scale() {
    return (this.zoom * 0.9 * Math.min(this.width, this.height)) / this.span;
  }

  /** Unit vectors (world, 3-D) of the screen's right, up and towards the viewer. */
  axes() {
    const [ca, sa] = [Math.cos(this.azimuth), Math.sin(this.azimuth)];
    const [ce, se] = [Math.cos(this.elevation), Math.sin(this.elevation)];
    const u = this.up, a = (u + 1) % 3, b = (u + 2) % 3; // (a, b, up) right-handed
    const right = [0, 0, 0], top = [0, 0, 0], toward = [0, 0, 0];
    // the report's convention: azimuth 0 looks from -b towards +b, with +a to the right
    right[a] = ca; right[b] = sa;
    top[a] = -se * sa; top[b] = se * ca; top[u] = ce;
    toward[a] = ce * sa; toward[b] = -ce * ca; toward[u] = se;
    return [right, top, toward];
  }

  /** Screen x, y (px) of `n` points of `positions` into `out` (2n), depths into `depth`. */
  project(positions, n, out, depth) {
    const s = this.scale, cx = this.width / 2, cy = this.height / 2, c = this.centre;
    if (this.dim === 2) {
      for (let i = 0; i < n; i++) {
        out[2 * i] = cx + s * (positions[2 * i] - c[0]);
        out[2 * i + 1] = cy - s * (positions[2 * i + 1] - c[1]);
      }
      return;
    }
    const [r, t, f] = this.axes();
    for (let i = 0; i < n; i++) {
      const x = positions[3 * i] - c[0], y = positions[3 * i + 1] - c[1];
      const z = positions[3 * i + 2] - c[2];
      out[2 * i] = cx + s * (r[0] * x + r[1] * y + r[2] * z);
      out[2 * i + 1] = cy - s * (t[0] * x + t[1] * y + t[2] * z);
      depth[i] = f[0] * x + f[1] * y + f[2] * z;
    }
  }

  /** The world point under screen (px, py) at `depth` towards the viewer (3-D). */
  unproject(px, py, depth) {
    const s = this.scale, c = this.centre;
    const u = (px - this.width / 2) / s, v = (this.height / 2 - py) / s;
    if (this.dim === 2) return [c[0] + u, c[1] + v];
    const [r, t, f] = this.axes();
    return [0, 1, 2].map((k) => c[k] + u * r[k] + v * t[k] + depth * f[k]);
  }
}

/** The springs and particles to draw: all, or (`outside`) those on the body's surface,
 * whose particles have fewer springs than the most any has: inside a very dense 3-D body
 * nothing shows, and its springs would cost most of a frame. */
function surface(springs, n, outside) {
  const all = (count) => Uint32Array.from({ length: count }, (_, i) => i);
  if (!outside) return { springs: all(springs.length / 2), particles: all(n) };
  const degree = new Uint32Array(n);
  for (const p of springs) degree[p]++;
  const most = degree.reduce((a, b) => Math.max(a, b), 0);
  const particles = all(n).filter((i) => degree[i] < most);
  const kept = all(springs.length / 2).filter(
    (e) => degree[springs[2 * e]] < most && degree[springs[2 * e + 1]] < most);
  return { springs: kept, particles };
}

/** A canvas's pixels as 32-bit words, for drawing many 1-px lines fast. */
class Pixels {
  constructor(canvas, scene) {
    this.width = canvas.width;
    this.height = canvas.height;
    this.context = canvas.getContext("2d");
    this.image = this.context.createImageData(this.width, this.height);
    this.words = new Uint32Array(this.image.data.buffer);
    this.colours = scene.colours.map((hex) => this.word(hex, 1));
    this.strokes = Uint8Array.from(scene.stroke_of_level); // each level's line, as `line` takes
    this.dark = this.word("#4d4d4d", 1);
    this.dotColour = this.word("#262626", 0.8);
  }

  /** The 32-bit word (little-endian RGBA) of `hex` drawn with `alpha` over white. */
  word(hex, alpha) {
    const [r, g, b] = [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16));
    const over = (c) => Math.round(alpha * c + (1 - alpha) * 255);
    return ((255 << 24) | (over(b) << 16) | (over(g) << 8) | over(r)) >>> 0;
  }

  clear() {
    this.words.fill(0xffffffff);
  }

  /** A line (a DDA: one pixel per step along the longer axis); `stroke` 0: 1 px dashed,
   * 3 pixels on and 2 off, 1: 1 px, 2: 2 px wide (the classes of `strain_style.STROKES`). */
  line(x0, y0, x1, y1, colour, stroke = 1) {
    const steps = Math.ceil(Math.max(Math.abs(x1 - x0), Math.abs(y1 - y0)));
    const dx = (x1 - x0) / (steps || 1), dy = (y1 - y0) / (steps || 1);
    const { width, height, words } = this;
    const across = stroke === 2 ? (Math.abs(dx) > Math.abs(dy) ? width : 1) : 0;
    let x = x0 + 0.5, y = y0 + 0.5;
    for (let i = 0; i <= steps; i++, x += dx, y += dy) {
      if (stroke === 0 && i % 5 >= 3) continue;
      if (x >= 0 && y >= 0 && x < width - 1 && y < height - 1) {
        const k = (y | 0) * width + (x | 0);
        words[k] = words[k + across] = colour;
      }
    }
  }

  /** A dot of `size` × `size` pixels (1 or 2). */
  dot(x, y, colour, size) {
    const { width, height, words } = this;
    const i = Math.floor(x), j = Math.floor(y);
    if (i < 0 || j < 0 || i + 1 >= width || j + 1 >= height) return;
    words[j * width + i] = colour;
    if (size > 1) words[j * width + i + 1] = words[(j + 1) * width + i] = colour;
    if (size > 1) words[(j + 1) * width + i + 1] = colour;
  }

  show() {
    this.context.putImageData(this.image, 0, 0);
  }
}

/** Draws the body, its floor, walls and balls on a 2-D canvas. */
class Painter {
  constructor(canvas, scene, springs, rest, fixed) {
    this.canvas = canvas;
    this.context = canvas.getContext("2d", { alpha: false });
    this.scene = scene;
    this.springs = springs;
    this.rest = rest;
    this.fixed = fixed;
    this.n = fixed.length;
    this.screen = new Float32Array(2 * this.n);
    this.depth = new Float32Array(this.n);
    this.levels = new Uint8Array(rest.length);
    this.order = new Uint32Array(rest.length);
    this.counts = new Uint32Array(LEVELS + 1);
    this.dense = rest.length > DENSE;
    if (this.dense) this.pixels = new Pixels(canvas, scene);
    this.shown = surface(springs, this.n, scene.dim === 3 && rest.length > SURFACE_ONLY);
    this.next = new Uint32Array(LEVELS);
    // the walls' and floor's segments: their ends, and where they are on the screen
    this.ends = Float32Array.from(scene.world.edges.flat(2));
    this.endsScreen = new Float32Array((2 * this.ends.length) / scene.dim);
    this.endsDepth = new Float32Array(this.ends.length / scene.dim);
  }

  /** The walls' and floor's segments on the screen: [x0, y0, x1, y1] per segment. */
  projectWorld(camera) {
    const { ends, endsScreen, endsDepth } = this;
    camera.project(ends, endsDepth.length, endsScreen, endsDepth);
    return endsScreen;
  }

  /** The positions to draw: ``positions`` with particle ``hand.particle`` at ``hand.target``
   * (into a buffer reused from frame to frame). */
  place(positions, hand) {
    if (this.placed?.length !== positions.length) this.placed = new Float32Array(positions.length);
    this.placed.set(positions);
    const d = this.scene.dim;
    for (let k = 0; k < d; k++) this.placed[d * hand.particle + k] = hand.target[k];
    return this.placed;
  }

  draw(camera, positions, held, focus = null) {
    const g = this.context, { width, height } = this.canvas;
    camera.project(positions, this.n, this.screen, this.depth);
    if (this.dense) {
      this.drawDense(camera, positions);
    } else {
      g.fillStyle = "#fff";
      g.fillRect(0, 0, width, height);
      this.drawWorld(g, camera);
      this.sortByStrain(positions);
      this.drawSprings(g);
      this.drawParticles(g);
    }
    this.drawHeld(g, held);
    this.drawBalls(g, camera);
    this.drawFocus(g, focus);
  }

  /** The keyboard's focus: a dark blue ring (white inside, to show on dark springs). */
  drawFocus(g, focus) {
    if (focus === null) return;
    const [x, y] = [this.screen[2 * focus], this.screen[2 * focus + 1]];
    for (const [colour, width, radius] of [["#fff", 5, 12], ["#1a5fb4", 2.5, 12]]) {
      g.strokeStyle = colour;
      g.lineWidth = width;
      g.beginPath();
      g.arc(x, y, radius, 0, 2 * Math.PI);
      g.stroke();
    }
  }

  /** Thousands of springs: 1-px lines written into the pixels, one pass, no paths. */
  drawDense(camera, x) {
    const { springs, rest, screen, pixels } = this;
    const d = this.scene.dim, limit = this.scene.strain_limit;
    pixels.clear();
    const ends = this.projectWorld(camera);
    for (let i = 0; i < ends.length; i += 4) {
      pixels.line(ends[i], ends[i + 1], ends[i + 2], ends[i + 3], pixels.dark);
    }
    const { springs: shown, particles } = this.shown;
    for (let s = 0; s < shown.length; s++) {
      const e = shown[s], a = springs[2 * e], b = springs[2 * e + 1];
      let sum = 0;
      for (let k = 0; k < d; k++) sum += (x[d * a + k] - x[d * b + k]) ** 2;
      const level = Math.floor(((Math.sqrt(sum) / rest[e] - 1 + limit) / (2 * limit)) * LEVELS);
      const l = level < 0 ? 0 : level >= LEVELS ? LEVELS - 1 : level;
      pixels.line(screen[2 * a], screen[2 * a + 1], screen[2 * b], screen[2 * b + 1],
        pixels.colours[l], pixels.strokes[l]);
    }
    const size = this.n > 2000 ? 1 : 2; // a dense body: its springs show between the dots
    for (const i of particles) pixels.dot(screen[2 * i], screen[2 * i + 1], pixels.dotColour, size);
    pixels.show();
  }

  drawHeld(g, held) {
    if (held === null) return;
    g.strokeStyle = HELD_COLOUR;
    g.lineWidth = 3;
    g.beginPath();
    g.arc(this.screen[2 * held], this.screen[2 * held + 1], 8, 0, 2 * Math.PI);
    g.stroke();
  }

  /** Each spring's colour level, and the springs in level order (a counting sort). */
  sortByStrain(x) {
    const { springs, rest, levels, order, counts } = this;
    const d = this.scene.dim, limit = this.scene.strain_limit;
    counts.fill(0);
    for (let e = 0; e < rest.length; e++) {
      const a = d * springs[2 * e], b = d * springs[2 * e + 1];
      let sum = 0;
      for (let k = 0; k < d; k++) sum += (x[a + k] - x[b + k]) ** 2;
      const strain = Math.sqrt(sum) / rest[e] - 1;
      const level = Math.floor(((strain + limit) / (2 * limit)) * LEVELS);
      levels[e] = level < 0 ? 0 : level >= LEVELS ? LEVELS - 1 : level;
      counts[levels[e] + 1]++;
    }
    for (let l = 1; l <= LEVELS; l++) counts[l] += counts[l - 1];
    const next = this.next;
    next.set(counts.subarray(0, LEVELS));
    for (let e = 0; e < rest.length; e++) order[next[levels[e]]++] = e;
  }

  /** The springs a path per level, in its colour and its class's width and dash. */
  drawSprings(g) {
    const { springs, order, counts, screen } = this;
    const { strokes, stroke_of_level: strokeOf } = this.scene;
    let stroke = -1;
    for (let l = 0; l < LEVELS; l++) {
      if (counts[l] === counts[l + 1]) continue;
      if (strokeOf[l] !== stroke) { // the levels' classes in order: two changes at most
        stroke = strokeOf[l];
        g.lineWidth = strokes[stroke].width;
        g.setLineDash(strokes[stroke].dash);
      }
      g.beginPath();
      for (let i = counts[l]; i < counts[l + 1]; i++) {
        const a = 2 * springs[2 * order[i]], b = 2 * springs[2 * order[i] + 1];
        g.moveTo(screen[a], screen[a + 1]);
        g.lineTo(screen[b], screen[b + 1]);
      }
      g.strokeStyle = this.scene.colours[l];
      g.stroke();
    }
    g.setLineDash([]);
  }

  drawParticles(g) {
    const { screen, fixed, n } = this;
    const size = n > 300 ? 2 : 4;
    g.fillStyle = "#262626";
    g.beginPath();
    for (let i = 0; i < n; i++) {
      if (!fixed[i]) g.rect(screen[2 * i] - size / 2, screen[2 * i + 1] - size / 2, size, size);
    }
    g.fill();
    g.fillStyle = "#000";
    for (let i = 0; i < n; i++) {
      if (fixed[i]) g.fillRect(screen[2 * i] - 3, screen[2 * i + 1] - 3, 6, 6);
    }
  }

  drawBalls(g, camera) {
    g.fillStyle = "rgba(44, 160, 44, 0.6)";
    for (const [particle, radius] of this.scene.spheres) {
      g.beginPath();
      g.arc(this.screen[2 * particle], this.screen[2 * particle + 1],
        radius * camera.scale, 0, 2 * Math.PI);
      g.fill();
    }
  }

  /** The scene's walls (a box) and floor (a grid on its plane). */
  drawWorld(g, camera) {
    const ends = this.projectWorld(camera);
    g.strokeStyle = "#4d4d4d";
    g.lineWidth = 2;
    g.beginPath();
    for (let i = 0; i < ends.length; i += 4) {
      g.moveTo(ends[i], ends[i + 1]);
      g.lineTo(ends[i + 2], ends[i + 3]);
    }
    g.stroke();
  }
}

/** PhET-style bars of the energy now, and the total against time. */
class EnergyPanel {
  constructor(parent, unit) {
    this.canvas = element("canvas", { width: 260, height: 480 }, parent);
    this.canvas.className = "msdlab-energy";
    this.canvas.setAttribute("role", "img");
    this.canvas.setAttribute("aria-label", "energy bars, and the total against time "
      + "(the table after them gives the numbers)");
    this.canvas.style.maxWidth = "100%";
    this.table = element("table", { className: "msdlab-energy-table msdlab-hidden" }, parent);
    element("caption", { textContent: `energy now (${unit})` }, this.table);
    this.rows = element("tbody", {}, this.table);
    this.tabled = -Infinity;
    this.unit = unit;
    this.history = [];
    this.bars = {};
  }

  /** The bars' numbers in the table, every `TABLE_EVERY` ms at most. */
  tabulate() {
    const now = performance.now();
    if (now - this.tabled < TABLE_EVERY) return;
    this.tabled = now;
    this.rows.replaceChildren(...[...Object.entries(this.bars), ["total", this.total ?? 0]]
      .map(([name, value]) => {
        const row = element("tr");
        element("th", { textContent: name, scope: "row" }, row);
        element("td", { textContent: value.toPrecision(3) }, row);
        return row;
      }));
  }

  /** The bars: the energies in the body, what each mechanism took out, and the work put
   * in by the hand and by driven particles (the ledger books it negative, as taken out:
   * shown as the positive work done); the total, in the body + taken out - put in, stays
   * level. */
  update(energy) {
    if (!energy) return;
    const bars = { kinetic: energy.kinetic, elastic: energy.elastic,
      gravitational: energy.gravitational };
    if (energy.other) bars["other potential"] = energy.other;
    let sum = Object.values(bars).reduce((s, v) => s + v, 0);
    const booked = [];
    for (const [name, value] of Object.entries(energy.dissipated)) {
      const label = PUT_IN[name] ?? name;
      bars[label] = label === name ? value : -value;
      sum += value;
      booked.push(label);
    }
    const top = Math.max(...Object.values(bars).map(Math.abs));
    for (const label of booked) {
      if (Math.abs(bars[label]) <= 1e-9 * top) delete bars[label]; // nothing booked yet
    }
    this.bars = bars;
    this.total = sum;
    this.canvas.dataset.bars = JSON.stringify(bars);
    this.canvas.dataset.total = String(sum);
    this.history.push([energy.time, sum, energy.kinetic + energy.elastic + energy.gravitational
      + (energy.other || 0)]);
    if (this.history.length > HISTORY) this.history.shift();
    this.stale = true;
  }

  /** Draw the bars and the plot if new energies came since the last frame: redrawing the
   * same picture would cost the page a canvas upload every frame for nothing. */
  drawIfNew() {
    if (this.stale !== false) this.draw();
    this.stale = false;
  }

  draw() {
    const g = this.canvas.getContext("2d"), { width, height } = this.canvas;
    g.fillStyle = "#fafafa";
    g.fillRect(0, 0, width, height);
    const entries = [...Object.entries(this.bars), ["total", this.total ?? 0]];
    const top = Math.max(1e-12, ...entries.map(([, v]) => Math.abs(v)));
    const barHeight = 300 / Math.max(entries.length, 1);
    const colours = BAR_COLOURS;
    g.font = "11px sans-serif";
    entries.forEach(([name, value], i) => {
      const y = 8 + i * barHeight, w = (Math.abs(value) / top) * (width - 20);
      g.fillStyle = colours[name] ?? "#d62728";
      g.globalAlpha = value < 0 ? 0.4 : 1;
      g.fillRect(10, y + 13, w, barHeight - 18);
      g.globalAlpha = 1;
      g.fillStyle = "#000";
      g.fillText(`${name} ${value.toPrecision(3)} ${this.unit}`, 10, y + 10);
    });
    this.drawHistory(g, width, height);
    this.tabulate();
  }

  drawHistory(g, width, height) {
    const top = 330, bottom = height - 20, points = this.history;
    g.fillStyle = "#000";
    g.fillText("total (black), in the body (grey) vs time", 10, top - 4);
    if (points.length < 2) return;
    const t0 = points[0][0], t1 = points[points.length - 1][0] || t0 + 1;
    const values = points.flatMap((p) => [p[1], p[2]]);
    const least = Math.min(...values), most = Math.max(...values);
    const pad = Math.max(0.1 * (most - least), 1e-6 * Math.abs(most), 1e-12);
    const low = least - pad, high = most + pad;
    for (const [column, colour] of [[1, "#000"], [2, "#999"]]) {
      g.strokeStyle = colour;
      g.beginPath();
      points.forEach((p, i) => {
        const x = 10 + ((p[0] - t0) / (t1 - t0 || 1)) * (width - 20);
        const y = bottom - ((p[column] - low) / (high - low)) * (bottom - top);
        if (i === 0) g.moveTo(x, y);
        else g.lineTo(x, y);
      });
      g.stroke();
    }
  }
}

/** What a view counted (for benchmarks and tests): frames (requestAnimationFrame calls),
 * pictures drawn (frames in which something changed), new positions shown (updates),
 * states received from the kernel (`received`, the live view's),
 * new pictures (frames showing positions that differ from the frame before) and the
 * times (ms) of the last `PICTURE_TIMES` of them, and the delays (ms) from a mouse move
 * to the frame drawing the held particle at the hand (`drawDelays`) and to the first
 * positions from the engine with it there (`engineDelays`).
 * Each view is listed in `window.msdlabViews`. */
function newStats() {
  return { frames: 0, drawn: 0, updates: 0, received: 0, pictures: 0, pictureTimes: [],
    drawDelays: [], engineDelays: [], moved: null, pending: null };
}

/** Whether two position arrays hold different numbers. */
function differ(a, b) {
  if (a === b) return false;
  if (!b || a.length !== b.length) return true;
  for (let i = 0; i < a.length; i++) if (a[i] !== b[i]) return true;
  return false;
}

/** Count a new picture (positions unlike the last shown) at time `now` (ms). */
function countPicture(stats, now) {
  stats.pictures++;
  stats.pictureTimes.push(now);
  if (stats.pictureTimes.length > PICTURE_TIMES) stats.pictureTimes.shift();
}

/** Whether particle `p` of `x` (dimension `d`) is at `target`, to float32's precision. */
function isAt(x, p, target, d) {
  let miss = 0;
  for (let k = 0; k < d; k++) miss = Math.max(miss, Math.abs(x[d * p + k] - target[k]));
  return miss <= 1e-3 * (1 + Math.abs(target[0]));
}

/** A body view: canvas, camera, mouse and the drawing loop. `source` hands it
 * positions (`latest()`) and takes the user's grabs (`grab/move/release`, each grab and
 * move with the time of the event, ms). */
export function mountView(el, scene, arrays, source) {
  addStyle();
  const root = element("div", { className: "msdlab-live" }, el);
  root.style.cssText = "font: 12px sans-serif; max-width: 100%";
  const row = element("div", {}, root);  // the energy panel wraps below a narrow view
  row.style.cssText = "display: flex; flex-wrap: wrap; align-items: flex-start; gap: 6px";
  const canvas = bodyCanvas(row, scene, !!source.grab);
  const energy = scene.energy ? new EnergyPanel(row, scene.energy_unit) : null;
  strainKey(root, scene);
  const status = element("div", { className: "msdlab-status" }, root);
  const camera = new Camera(scene, canvas.width, canvas.height);
  const painter = new Painter(canvas, scene, arrays.springs, arrays.rest, arrays.fixed);
  const stats = newStats();
  // `hand`: the held particle and where the hand put it (world coordinates); `focus`: the
  // particle the keyboard is on; `said`: what the keys did, said at once; `told`: what the
  // body does, said every `SAY_EVERY` ms at most
  const view = { root, canvas, status, energy, camera, painter, stats, held: null, hand: null,
    focus: null, positions: null, alive: true, said: new Announcer(root, 0, "msdlab-said"),
    told: new Announcer(root, SAY_EVERY, "msdlab-told") };
  window.msdlabViews = window.msdlabViews || [];
  window.msdlabViews.push(view);
  pointer(view, painter, source);
  canvasKeys(view, scene, source);
  let last = null, shown = [];
  const frame = () => {
    if (!view.alive) return;
    const positions = source.latest();
    view.positions = positions;
    if (positions) {
      if (positions !== last) {
        stats.updates++;
        if (differ(positions, last)) countPicture(stats, performance.now());
        checkDelay(stats, positions, scene.dim);
      }
      letGo(view, positions, scene.dim);
      // Grab pins the held particle to the hand at the engine's next step: draw it there
      // now, not a round trip through the kernel later (only while the engine steps)
      const hand = source.stepping?.() ? view.hand : null;
      const readings = source.readings?.() ?? null;
      // drawn again only if something changed: the same picture would cost a canvas upload
      // the keyboard's focus ring, not a mouse's click's (the browser's :focus-visible)
      const focus = canvas.matches(":focus-visible") ? view.focus : null;
      const now = [positions, hand, view.held, camera.azimuth, camera.elevation, camera.zoom,
        readings, focus, painter.fixed];
      if (now.some((value, i) => value !== shown[i])) {
        painter.draw(camera, hand ? painter.place(positions, hand) : positions, view.held, focus);
        if (readings) drawInstruments(painter, camera, readings);
        stats.drawn++;
        if (hand && stats.moved !== null) stats.drawDelays.push(performance.now() - stats.moved);
        shown = now;
      }
      stats.moved = null;
      last = positions;
    }
    if (energy) energy.drawIfNew();
    stats.frames++;
    requestAnimationFrame(frame);
  };
  requestAnimationFrame(frame);
  return view;
}

/** The key to the springs: a sample of each class's line with its name (for the eye), and
 * the key in words (for a screen reader). */
function strainKey(parent, scene) {
  const key = element("div", { className: "msdlab-key" }, parent);
  key.style.cssText = "margin: 4px 0; display: flex; flex-wrap: wrap; gap: 4px 14px; "
    + "align-items: center; color: #333";
  const shown = element("span", { textContent: "springs:" }, key);
  shown.setAttribute("aria-hidden", "true");
  for (const stroke of [...scene.strokes].reverse()) {
    const item = element("span", {}, key);
    item.setAttribute("aria-hidden", "true");
    item.append(strokeSample(stroke), ` ${stroke.name}`);
  }
  element("span", { className: "msdlab-hidden", textContent: scene.key }, key);
  return key;
}

/** A short line drawn as `stroke` draws springs (a border: dashed or solid). */
function strokeSample({ width, dash, colour }) {
  const line = element("span");
  line.style.cssText = "display: inline-block; width: 30px; margin-right: 4px; "
    + `vertical-align: middle; border-top: ${width}px ${dash.length ? "dashed" : "solid"} ${colour}`;
  return line;
}

/** The body's canvas: focusable, named, its keys in a description (`live`: a live view's,
 * whose particles the hand takes). */
function bodyCanvas(parent, scene, live) {
  const canvas = element("canvas", { width: scene.width, height: scene.height }, parent);
  canvas.className = "msdlab-canvas";
  canvas.tabIndex = 0;
  canvas.setAttribute("role", "application");
  canvas.setAttribute("aria-roledescription", "simulation");
  canvas.setAttribute("aria-label", "the body");
  const help = element("p", { className: "msdlab-hidden", id: `msdlab-keys-${++views}`,
    textContent: (live ? "A pointer drags a particle. Keys: the arrow keys move the focus to "
      + "the nearest particle that way, n and shift n to the next and previous by number, "
      + "or type its number; Enter picks it up and lets it go, the arrow keys then move it, "
      + "plus and minus change their step, Escape lets go; p pins or frees it. " : "")
      + (scene.dim === 3 ? "Shift and the arrow keys turn the view, Page Up and Page Down "
        + "zoom; a pointer drags empty space to turn it, the wheel zooms." : "") }, parent);
  canvas.setAttribute("aria-describedby", help.id);
  canvas.style.cssText = "cursor: crosshair; border: 1px solid #ccc; max-width: 100%; height: auto";
  return canvas;
}

/** Time from a mouse move to the first engine positions with the held particle where it
 * was sent. */
function checkDelay(stats, x, d) {
  if (!stats.pending) return;
  const [time, particle, target] = stats.pending;
  if (isAt(x, particle, target, d)) {
    stats.engineDelays.push(performance.now() - time);
    stats.pending = null;
  }
}

/** After a release, the page draws the particle at the hand until the engine has it there
 * too (or for a second at most), so it does not jump back to a position a round trip old. */
function letGo(view, x, d) {
  const hand = view.hand;
  if (hand?.released && (isAt(x, hand.particle, hand.target, d)
      || performance.now() - hand.released > 1000)) view.hand = null;
}

/** Grab and orbit with pointer events: a mouse, a finger or a pen. */
function pointer(view, painter, source) {
  const { canvas, camera, stats } = view;
  let turning = null, depth = 0, active = null; // `active`: the pointer holding or turning
  canvas.style.touchAction = "none"; // a finger drags a particle, not the page
  const at = (event) => { // the canvas's pixel under the mouse (inside its border)
    const box = canvas.getBoundingClientRect();
    return [(event.clientX - box.left - canvas.clientLeft) * (canvas.width / canvas.clientWidth),
      (event.clientY - box.top - canvas.clientTop) * (canvas.height / canvas.clientHeight)];
  };
  /** The hand at `target` (world) now: drawn at the next frame, sent to the engine. */
  const hold = (particle, target, event) => {
    const time = Math.min(event.timeStamp, performance.now()); // when the event was made
    view.hand = { particle, target, time, released: null };
    stats.moved = time;
    stats.pending = [time, particle, target];
  };
  canvas.addEventListener("contextmenu", (event) => event.preventDefault());
  canvas.addEventListener("pointerdown", (event) => {
    if (active !== null) return; // one hand at a time
    const [px, py] = at(event);
    const nearest = event.button === 0 && source.grab ? pick(painter, px, py) : null;
    if (nearest === null) {
      turning = camera.dim === 3 ? [px, py, camera.azimuth, camera.elevation] : null;
      if (turning) take(event);
      return;
    }
    take(event);
    // in 3-D the hand moves on the plane facing the camera through the particle
    view.held = view.focus = nearest; // the keys go on from the particle taken
    depth = painter.depth[nearest];
    hold(nearest, camera.unproject(px, py, depth), event);
    source.grab(nearest, view.hand.target, view.hand.time);
  });
  const take = (event) => {
    active = event.pointerId;
    try { canvas.setPointerCapture(event.pointerId); } catch { /* a pointer already gone */ }
  };
  canvas.addEventListener("pointermove", (event) => {
    if (event.pointerId !== active) return;
    const [px, py] = at(event);
    if (view.held !== null) {
      hold(view.held, camera.unproject(px, py, depth), event);
      source.move(view.hand.target, view.hand.time);
    } else if (turning) {
      camera.azimuth = turning[2] - (px - turning[0]) * 0.01;
      const elevation = turning[3] + (py - turning[1]) * 0.01;
      camera.elevation = Math.max(-1.55, Math.min(1.55, elevation));
    }
  });
  const letGoOf = (event) => {
    if (event.pointerId !== active) return;
    if (view.held !== null) source.release();
    if (view.hand) view.hand.released = performance.now();
    view.held = null;
    turning = null;
    active = null;
  };
  canvas.addEventListener("pointerup", letGoOf);
  canvas.addEventListener("pointercancel", letGoOf);
  canvas.addEventListener("lostpointercapture", letGoOf); // the page took the pointer away
  canvas.addEventListener("wheel", (event) => {
    event.preventDefault();
    camera.zoom *= Math.exp(-event.deltaY * 0.001);
  }, { passive: false });
}

const DIRECTIONS = { ArrowRight: [1, 0], ArrowLeft: [-1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1] };

/** The particle nearest `from` on the screen in direction `[dx, dy]` (px, y down): the
 * least distance along it plus twice the distance across; null if none is that way. */
function nearestToward(painter, from, [dx, dy]) {
  const s = painter.screen, x0 = s[2 * from], y0 = s[2 * from + 1];
  let best = null, least = Infinity;
  for (let i = 0; i < painter.n; i++) {
    const along = (s[2 * i] - x0) * dx + (s[2 * i + 1] - y0) * dy;
    const across = Math.abs((s[2 * i] - x0) * dy - (s[2 * i + 1] - y0) * dx);
    if (i !== from && along > 0.5 && along + 2 * across < least) [best, least] = [i, along + 2 * across];
  }
  return best;
}

/** The particle nearest the middle of the body on the screen: the keyboard starts there. */
function middleParticle(painter) {
  const s = painter.screen, n = painter.n;
  let mx = 0, my = 0;
  for (let i = 0; i < n; i++) [mx, my] = [mx + s[2 * i] / n, my + s[2 * i + 1] / n];
  let best = 0, least = Infinity;
  for (let i = 0; i < n; i++) {
    const d = (s[2 * i] - mx) ** 2 + (s[2 * i + 1] - my) ** 2;
    if (d < least) [best, least] = [i, d];
  }
  return best;
}

/** A round step for the keyboard's hand: a fiftieth of the view's span, to 1, 2 or 5. */
function roundStep(span) {
  const raw = span / 50, ten = 10 ** Math.floor(Math.log10(raw));
  return Number([1, 2, 5, 10].map((m) => m * ten).find((v) => v >= raw * 0.7).toPrecision(2));
}

/** The canvas's keys (WCAG 2.1.1): the focus among particles (arrows, n, shift n, a number),
 * the hand (Enter takes and lets go, the arrows move it by `step`, + and - change the step,
 * Escape lets go), p pins; in 3-D shift and the arrows turn, Page Up and Down zoom. */
function canvasKeys(view, scene, source) {
  const { canvas, painter, camera } = view;
  const keys = { step: roundStep(scene.span), typed: "", typedAt: 0, moved: 0 };
  const unit = scene.length_unit ?? "";
  const where = (p) => `particle ${p} of ${painter.n}${painter.fixed[p] ? ", pinned" : ""}`
    + (view.positions ? `, at ${placeOf(view.positions, p, scene)}` : "");
  const focusOn = (p) => {
    if (p === null || p < 0 || p >= painter.n) return;
    view.focus = p;
    view.said.say(where(p));
  };
  canvas.addEventListener("focus", () => focusOn(view.focus ?? middleParticle(painter)));
  const hand = {
    take(event) {
      const p = view.focus, d = scene.dim;
      const target = Array.from(view.positions.subarray(d * p, d * p + d));
      view.held = p;
      view.hand = { particle: p, target, time: eventTime(event), released: null };
      keys.moved = view.hand.time;
      source.grab(p, target, view.hand.time);
      view.said.say(`picked up particle ${p}: the arrow keys move it by ${keys.step} ${unit}, `
        + "Enter lets go");
    },
    move(event, [dx, dy]) {
      const [right, top] = scene.dim === 3 ? camera.axes() : [[1, 0], [0, 1]];
      const from = view.hand.target, time = eventTime(event);
      const target = from.map((c, k) => c + keys.step * (dx * right[k] - dy * top[k]));
      source.move(from, Math.max(time - GLIDE, keys.moved)); // where the hand stood till then
      source.move(target, time);
      view.hand = { ...view.hand, target, time };
      keys.moved = time;
      view.said.say(`particle ${view.held} at ${placeAt(target, scene)}`);
    },
    letGo() {
      source.release();
      view.hand.released = performance.now();
      view.said.say(`let go of particle ${view.held} at ${placeAt(view.hand.target, scene)}`);
      view.held = null;
    },
  };
  canvas.addEventListener("keydown", (event) => {
    if (event.ctrlKey || event.metaKey || event.altKey) return;
    const done = keyOnCanvas(event, view, scene, source, keys, hand, focusOn);
    if (!done) return;
    event.preventDefault();
    event.stopPropagation();
  });
}

/** Where a target (world coordinates) is, in words. */
function placeAt(target, scene) {
  return placeOf(Float32Array.from(target), 0, scene);
}

/** When an event was made (ms, the page's clock). */
function eventTime(event) {
  return Math.min(event.timeStamp, performance.now());
}

/** One key on the canvas; whether it was the canvas's. */
function keyOnCanvas(event, view, scene, source, keys, hand, focusOn) {
  const { camera, painter } = view, key = event.key, direction = DIRECTIONS[key];
  if (direction && event.shiftKey && scene.dim === 3) {
    camera.azimuth -= 0.1 * direction[0];
    camera.elevation = Math.max(-1.55, Math.min(1.55, camera.elevation - 0.1 * direction[1]));
  } else if (key === "PageUp" || key === "PageDown") {
    camera.zoom *= key === "PageUp" ? 1.1 : 1 / 1.1;
  } else if (!source.grab || view.focus === null) {
    return false;
  } else if (direction && view.held !== null) {
    hand.move(event, direction);
  } else if (direction) {
    focusOn(nearestToward(painter, view.focus, direction));
  } else if (key === "Enter") {
    if (view.held === null) hand.take(event);
    else hand.letGo();
  } else if (key === "Escape" && view.held !== null) {
    hand.letGo();
  } else if (key === "n" || key === "N") {
    focusOn((view.focus + (key === "n" ? 1 : painter.n - 1)) % painter.n);
  } else if (/^[0-9]$/.test(key)) {
    const now = performance.now();
    keys.typed = (now - keys.typedAt < 1000 ? keys.typed : "") + key;
    keys.typedAt = now;
    focusOn(Number(keys.typed) < painter.n ? Number(keys.typed) : null);
  } else if (key === "p") {
    source.pin?.(view.focus);
  } else if (key === "+" || key === "=" || key === "-") {
    keys.step = roundStep(keys.step * (key === "-" ? 25 : 100));
    view.said.say(`step ${keys.step} ${scene.length_unit ?? ""}`);
  } else {
    return false;
  }
  return true;
}

/** The free particle nearest to screen (px, py), within PICK_RADIUS, or null. */
function pick(painter, px, py) {
  let best = null, nearest = PICK_RADIUS ** 2;
  for (let i = 0; i < painter.n; i++) {
    const d = (painter.screen[2 * i] - px) ** 2 + (painter.screen[2 * i + 1] - py) ** 2;
    if (d < nearest) [best, nearest] = [i, d];
  }
  return best;
}

/** A button in `parent` calling `act`; `title` is also its name for screen readers. */
function button(parent, label, title, act) {
  const node = element("button", { textContent: label, title }, parent);
  node.setAttribute("aria-label", title);
  node.addEventListener("click", act);
  return node;
}

/** A labelled slider; `change(value)` on release of the handle. */
function slider(parent, setting, change) {
  const label = element("label", {}, parent);
  label.style.cssText = "display: inline-block; margin: 2px 10px 2px 0";
  const name = element("span", { textContent: setting.label + " " }, label);
  const input = element("input", { type: "range", min: setting.min, max: setting.max,
    step: setting.step, value: setting.value }, label);
  input.dataset.setting = setting.name;
  input.setAttribute("aria-label", setting.label);
  input.style.verticalAlign = "middle";
  const format = (value) => Number(value).toPrecision(3);
  const shown = element("span", { textContent: format(setting.value) }, label);
  name.title = setting.rebuild ? "changing this rebuilds the scene" : "applied between steps";
  input.addEventListener("input", () => (shown.textContent = format(input.value)));
  input.addEventListener("change", () => change(Number(input.value)));
  return input;
}

/** anywidget's entry: the live view of a running simulation. */
function render({ model, el }) {
  const scene = model.get("scene");
  const arrays = {
    springs: typed(model.get("springs"), Int32Array),
    rest: typed(model.get("rest"), Float32Array),
    fixed: typed(model.get("fixed"), Uint8Array),
  };
  let positions = typed(model.get("positions"), Float32Array);
  const states = []; // states received, not shown yet, oldest first
  const send = (message) => model.send(message);
  const show = (state) => { // a state's positions, and its energies and status line if any
    positions = state.positions;
    if (state.energy && view.energy) view.energy.update(state.energy);
    if (state.energy) bar.tone.follow(state.energy);
    if (state.pace !== undefined) view.status.dataset.pace = String(state.pace);
    if (state.status !== undefined) view.status.dataset.line = state.status;
    if (state.status !== undefined && !model.get("error")) view.status.textContent = state.status;
    if (state.readings !== undefined) tools.update(state.readings);
  };
  let path = [], sending = null; // the hand's moves not sent yet: [time, ...target] each
  const sendPath = () => {
    clearTimeout(sending);
    sending = null;
    if (path.length) send({ type: "move", path });
    path = [];
  };
  const source = {
    latest: () => { // one state a frame
      if (states.length) show(states.shift());
      return positions;
    },
    // with the time of the hand's move (ms): the kernel plays the moves back at their pace
    grab: (particle, target, time) => send({ type: "grab", particle, target, time }),
    move: (target, time) => {
      path.push([time, ...target]);
      sending ??= setTimeout(sendPath, MOVES_EVERY);
    },
    release: () => {
      sendPath(); // the moves before it
      send({ type: "release" });
    },
    stepping: () => model.get("running") && !model.get("error"),
    readings: () => tools.shown(),
    pin: (particle) => send({ type: "pin", particle }),
  };
  const view = mountView(el, scene, arrays, source);
  const full = element("div", { className: "msdlab-full", hidden: true }, view.root);
  full.setAttribute("aria-live", "polite");
  const onPositions = () => (positions = typed(model.get("positions"), Float32Array));
  const onFixed = () => (view.painter.fixed = typed(model.get("fixed"), Uint8Array));
  const onMessage = (message, buffers) => {
    if (message.type === "export") download(message, buffers);
    if (message.type !== "state") return;
    if (message.words) view.told.say(message.words);
    if (message.full) [full.hidden, full.textContent] = [false, message.full];
    view.stats.received++;
    states.push({ ...message, positions: typed(buffers[0], Float32Array) });
    if (states.length > QUEUED) states.shift();
  };
  const onError = () => {
    const error = model.get("error");
    view.status.textContent = error ? `stopped: ${error}` : view.status.dataset.line ?? "";
    view.status.style.color = error ? "#b00" : "#333";
  };
  model.on("change:positions", onPositions);
  model.on("change:fixed", onFixed);
  model.on("msg:custom", onMessage);
  model.on("change:error", onError);
  const bar = controls(view.root, model, send);
  view.tone = bar.tone;
  const tools = instrumentPanel(view.root, model, send);
  view.root.insertBefore(full, view.status.nextSibling);
  keyboard(view.root, bar);
  onError();
  const report = reportFrames(view.stats, send);
  return () => {
    view.alive = false;
    clearInterval(report);
    clearTimeout(sending);
    tools.stop();
    view.said.stop();
    view.told.stop();
    bar.tone.stop();
    model.off("change:positions", onPositions);
    model.off("change:fixed", onFixed);
    model.off("msg:custom", onMessage);
    model.off("change:error", onError);
  };
}

/** Tell the kernel, every `REPORT_EVERY` ms, how many frames a second the page draws:
 * it sends that many states. The interval's id. */
function reportFrames(stats, send) {
  let frames = stats.frames, since = performance.now();
  return setInterval(() => {
    const now = performance.now();
    const rate = (1000 * (stats.frames - frames)) / (now - since);
    if (rate > 0) send({ type: "frames", rate });
    [frames, since] = [stats.frames, now];
  }, REPORT_EVERY);
}

/** Pause, step, reset, speed and the scene's settings; the controls by name, for the
 * keyboard. */
function controls(parent, model, send) {
  const bar = element("div", { className: "msdlab-controls" }, parent);
  const play = button(bar, "", "pause or run (space)", () => {
    model.set("running", !model.get("running"));
    model.save_changes();
  });
  const label = () => (play.textContent = model.get("running") ? "❚❚ pause" : "▶ run");
  model.on("change:running", label);
  label();
  const step = button(bar, "▶❚ step", "one step (s)", () => send({ type: "step" }));
  const reset = button(bar, "↺ reset", "back to the start (r)", () => send({ type: "reset" }));
  const describe = button(bar, "describe", "describe the state in words (d)",
    () => send({ type: "describe" }));
  const tone = new Tone();
  const sound = button(bar, "♪ tone", "a tone rising with the kinetic energy's share (a)",
    () => sound.setAttribute("aria-pressed", String(tone.toggle())));
  sound.setAttribute("aria-pressed", "false");
  const speed = { name: "speed", label: "speed ×", min: 0.1, max: 4, step: 0.1,
    value: model.get("speed") };
  const sliders = [slider(bar, speed, (value) => {
    model.set("speed", value);
    model.save_changes();
  })];
  const row = element("div", { className: "msdlab-settings" }, parent);
  for (const setting of model.get("settings")) {
    sliders.push(slider(row, setting, (value) => send({ type: "set", name: setting.name, value })));
  }
  return { play, step, reset, describe, sound, tone, sliders };
}

// ------------------------------------------------------------------ the instruments
// Python measures (msdlab/viz/instruments.py); the page draws what it reads.

const TOOLS = ["stopwatch", "ruler", "trace", "lines", "arrows"];
const TOOL_NAMES = { stopwatch: "stopwatch (simulated time) (w)",
  ruler: "ruler between the last two particles taken in hand (m)",
  trace: "trace of the particle last taken in hand, with its period (t)",
  lines: "natural-length and equilibrium lines of a hung mass (l)",
  arrows: "velocity and force arrows on the particle last taken in hand (v)" };
const ARROW = 60; // px: the longest arrow (PhET's vectors: scaled to show, not to units)

/** The ruler, the lines and the arrows over the body just drawn. */
function drawInstruments(painter, camera, readings) {
  const g = painter.context, screen = painter.screen;
  g.save();
  g.font = "12px sans-serif";
  if (readings.lines) drawLines(g, camera, readings.lines, painter.canvas.width);
  if (readings.ruler) {
    const [a, b] = readings.ruler.ends;
    const [ax, ay, bx, by] = [screen[2 * a], screen[2 * a + 1], screen[2 * b], screen[2 * b + 1]];
    g.strokeStyle = g.fillStyle = "#b8860b";
    g.lineWidth = 2;
    g.setLineDash([6, 3]);
    g.beginPath();
    g.moveTo(ax, ay);
    g.lineTo(bx, by);
    g.stroke();
    g.fillText(readings.ruler.distance.toPrecision(4), (ax + bx) / 2 + 6, (ay + by) / 2 - 6);
  }
  if (readings.arrows) drawArrows(g, painter, camera, readings.arrows);
  g.restore();
}

/** Dashed lines across the view through the natural-length and equilibrium points. */
function drawLines(g, camera, lines, width) {
  if (!lines) return;
  const at = new Float32Array(2), depth = new Float32Array(1);
  g.lineWidth = 1.5;
  g.setLineDash([8, 4]);
  for (const [name, colour] of [["natural", "#2a9d8f"], ["equilibrium", "#d62728"]]) {
    camera.project(Float32Array.from(lines[name]), 1, at, depth);
    g.strokeStyle = g.fillStyle = colour;
    g.beginPath();
    g.moveTo(0, at[1]);
    g.lineTo(width, at[1]);
    g.stroke();
    g.fillText(name === "natural" ? "natural length" : "equilibrium", 6, at[1] - 4);
  }
  g.setLineDash([]);
}

/** The velocity (green) and force (blue) on the traced particle, each scaled by the
 * largest seen so far, so that its length shows how it changes. */
function drawArrows(g, painter, camera, arrows) {
  const p = arrows.particle, d = camera.dim;
  painter.largest = painter.largest ?? { velocity: 0, force: 0 };
  const from = [painter.screen[2 * p], painter.screen[2 * p + 1]];
  g.setLineDash([]);
  g.lineWidth = 3;
  for (const [name, colour] of [["velocity", "#2ca02c"], ["force", "#1f77b4"]]) {
    const vector = arrows[name], size = Math.hypot(...vector);
    painter.largest[name] = Math.max(painter.largest[name], size);
    if (size === 0) continue;
    const [right, top] = d === 3 ? camera.axes() : [[1, 0], [0, 1]];
    const along = (axis) => vector.reduce((sum, v, k) => sum + v * axis[k], 0);
    const scale = ARROW / painter.largest[name];
    const to = [from[0] + scale * along(right), from[1] - scale * along(top)];
    arrow(g, from, to, colour);
  }
}

function arrow(g, [x0, y0], [x1, y1], colour) {
  const angle = Math.atan2(y1 - y0, x1 - x0), head = 8;
  g.strokeStyle = g.fillStyle = colour;
  g.beginPath();
  g.moveTo(x0, y0);
  g.lineTo(x1, y1);
  g.stroke();
  g.beginPath();
  g.moveTo(x1, y1);
  g.lineTo(x1 - head * Math.cos(angle - 0.4), y1 - head * Math.sin(angle - 0.4));
  g.lineTo(x1 - head * Math.cos(angle + 0.4), y1 - head * Math.sin(angle + 0.4));
  g.fill();
}

/** The instruments' toggles and readouts, gravity presets and the export buttons.
 * `update(readings)` shows the readings of a state; `shown()` is what to draw over the
 * body: the last readings, or null when no instrument is on. */
function instrumentPanel(parent, model, send) {
  const panel = element("div", { className: "msdlab-tools" }, parent);
  panel.setAttribute("role", "group");
  panel.setAttribute("aria-label", "instruments");
  element("span", { textContent: "instruments: " }, panel);
  for (const name of TOOLS) toggle(panel, model, name);
  const readouts = element("div", { className: "msdlab-readouts" }, parent);
  const watch = stopwatch(readouts, send);
  const trace = new TracePlot(readouts);
  const ruler = element("span", { className: "msdlab-ruler" }, readouts);
  ruler.setAttribute("aria-live", "off");
  const presets = element("div", { className: "msdlab-presets" }, parent);
  if (Object.keys(model.get("presets") ?? {}).length) {
    element("span", { textContent: "gravity: " }, presets);
  }
  presetButtons(presets, model, send);
  element("span", { textContent: "  export the run: " }, presets);
  exportButtons(presets, send);
  let last = {};
  const shown = () => (Object.values(model.get("tools") ?? {}).some(Boolean) ? last : null);
  const show = () => {
    const readings = shown() ?? {};
    watch.show(readings.stopwatch);
    trace.show(readings.trace, readings.time);
    ruler.hidden = !readings.ruler;
    if (readings.ruler) ruler.textContent = `ruler ${readings.ruler.distance.toPrecision(4)}`
      + ` between particles ${readings.ruler.ends.join(" and ")}`;
  };
  model.on("change:tools", show);
  show();
  return {
    update: (readings) => { last = readings; show(); },
    shown,
    stop: () => model.off("change:tools", show),
  };
}

/** A button that turns the instrument `name` on and off (the `tools` trait). */
function toggle(parent, model, name) {
  const node = button(parent, name, TOOL_NAMES[name], () => {
    model.set("tools", { ...model.get("tools"), [name]: !model.get("tools")?.[name] });
    model.save_changes();
  });
  node.dataset.tool = name;
  const show = () => {
    const on = !!model.get("tools")?.[name];
    node.setAttribute("aria-pressed", String(on));
    node.style.background = on ? "#cfe3f7" : "";
  };
  model.on("change:tools", show);
  show();
}

/** The stopwatch's reading and its start / stop and reset buttons. */
function stopwatch(parent, send) {
  const box = element("span", { className: "msdlab-stopwatch" }, parent);
  box.style.cssText = "margin-right: 12px; font-variant-numeric: tabular-nums";
  element("span", { textContent: "stopwatch " }, box);
  const reading = element("span", { textContent: "0.000" }, box);
  const unit = element("span", { textContent: "" }, box);
  reading.setAttribute("role", "timer");
  reading.setAttribute("aria-label", "stopwatch reading");
  let running = false;
  const go = button(box, "start", "start or stop the stopwatch",
    () => send({ type: "stopwatch", action: running ? "stop" : "start" }));
  button(box, "0", "reset the stopwatch", () => send({ type: "stopwatch", action: "reset" }));
  return {
    show(watch) {
      box.hidden = !watch;
      if (!watch) return;
      running = watch.running;
      reading.textContent = watch.reading.toFixed(3);
      unit.textContent = ` ${watch.unit} `;
      go.textContent = running ? "stop" : "start";
    },
  };
}

/** The traced particle's position and velocity against time, and its period. */
class TracePlot {
  constructor(parent) {
    this.canvas = element("canvas", { width: 320, height: 130 }, parent);
    this.canvas.className = "msdlab-trace";
    this.canvas.setAttribute("role", "img");
    this.canvas.setAttribute("aria-label", "trace of a particle's position and velocity");
    this.canvas.style.cssText = "vertical-align: top; border: 1px solid #ddd";
  }

  show(trace) {
    this.canvas.hidden = !trace;
    if (!trace) return;
    const g = this.canvas.getContext("2d"), { width, height } = this.canvas;
    const period = trace.period === null ? "not yet measured"
      : `${trace.period.toPrecision(5)} ${trace.unit}`;
    const axis = "xyz"[trace.axis];
    this.canvas.dataset.period = String(trace.period);
    this.canvas.setAttribute("aria-label", `trace of particle ${trace.particle}: `
      + `position ${axis} and velocity v${axis} against time; period ${period}`);
    g.fillStyle = "#fff";
    g.fillRect(0, 0, width, height);
    const points = trace.points;
    if (points.length > 1) {
      const t0 = points[0][0], t1 = points[points.length - 1][0];
      for (const [column, colour] of [[1, "#1f77b4"], [2, "#ff7f0e"]]) {
        const values = points.map((p) => p[column]);
        const low = Math.min(...values), high = Math.max(...values);
        g.strokeStyle = colour;
        g.beginPath();
        points.forEach((p, i) => {
          const x = 4 + ((p[0] - t0) / (t1 - t0 || 1)) * (width - 8);
          const y = height - 6 - ((p[column] - low) / (high - low || 1)) * (height - 30);
          if (i === 0) g.moveTo(x, y);
          else g.lineTo(x, y);
        });
        g.stroke();
      }
    }
    g.fillStyle = "#000";
    g.font = "11px sans-serif";
    g.fillText(`particle ${trace.particle}: ${axis} (blue), v${axis} (orange)   period ${period}`,
      4, 12);
  }
}

/** Buttons setting gravity to Earth's, the Moon's, Jupiter's or none (in the scene's
 * units), moving the gravity slider with it. */
function presetButtons(parent, model, send) {
  const presets = model.get("presets") ?? {};
  for (const [name, value] of Object.entries(presets)) {
    const node = button(parent, name, `gravity of ${name === "zero" ? "nothing" : name}: `
      + `|g| = ${value.toPrecision(3)}`, () => {
      const input = parent.closest(".msdlab-live")?.querySelector('input[data-setting="gravity"]');
      if (input) {
        input.value = value;
        input.dispatchEvent(new Event("input"));
      }
      send({ type: "set", name: "gravity", value });
    });
    node.dataset.gravity = name;
  }
}

function exportButtons(parent, send) {
  for (const kind of ["csv", "npz"]) {
    const node = button(parent, `⤓ ${kind.toUpperCase()}`,
      `download the run shown (time, energies, positions, velocities) as ${kind.toUpperCase()}`,
      () => send({ type: "export", format: kind }));
    node.dataset.export = kind;
  }
}

/** A file from the kernel (an export) handed to the browser to save. */
function download(content, buffers) {
  if (content?.type !== "export") return;
  const url = URL.createObjectURL(new Blob([buffers[0]]));
  const link = element("a", { href: url, download: content.name }, document.body);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10_000);
}

const TOOL_KEYS = { w: "stopwatch", m: "ruler", t: "trace", l: "lines", v: "arrows" };

/** Keys while the view has the focus: space pauses or runs, s steps, r resets, [ and ]
 * move the speed down or up, d describes the state in words, w, m, t, l and v turn the
 * instruments on and off, g goes to the next gravity, a turns the tone on and off (`Tone`);
 * Tab reaches every control and the
 * arrow keys move a slider. JupyterLab leaves the keys inside the view to it. */
function keyboard(root, bar) {
  root.tabIndex = 0;
  root.setAttribute("data-lm-suppress-shortcuts", "true");
  root.setAttribute("role", "region");
  root.setAttribute("aria-label", "msdlab live view. Keys: space pauses or runs, s steps, "
    + "r resets, [ and ] change the speed, d describes the state in words, w, m, t, l and v "
    + "turn the stopwatch, ruler, trace, lines and arrows on and off, g changes gravity, "
    + "a turns a tone following the kinetic energy on and off; "
    + "on the body, the arrow keys move the focus among particles and Enter picks one up");
  const nudge = (input, steps) => {
    input.value = Number(input.value) + steps * Number(input.step);
    input.dispatchEvent(new Event("input"));
    input.dispatchEvent(new Event("change"));
  };
  const click = (selector) => root.querySelector(selector)?.click();
  let gravity = -1;
  const nextGravity = () => {
    const presets = root.querySelectorAll("button[data-gravity]");
    if (presets.length) presets[(gravity = (gravity + 1) % presets.length)].click();
  };
  const keys = { " ": () => bar.play.click(), s: () => bar.step.click(),
    r: () => bar.reset.click(), "[": () => nudge(bar.sliders[0], -1),
    "]": () => nudge(bar.sliders[0], 1), d: () => bar.describe.click(), g: nextGravity,
    a: () => bar.sound.click() };
  for (const [key, tool] of Object.entries(TOOL_KEYS)) {
    keys[key] = () => click(`button[data-tool="${tool}"]`);
  }
  root.addEventListener("keydown", (event) => {
    const act = keys[event.key];
    const typing = event.target.tagName === "BUTTON" && event.key === " ";
    if (!act || typing || event.ctrlKey || event.metaKey || event.altKey) return;
    event.preventDefault();
    act();
  });
}

/** The replay page's player: recorded frames, play / pause, a scrubber, orbiting. It
 * starts playing, paused instead where the reader asked for reduced motion (WCAG 2.2.2:
 * the pause button stops it); keys: space plays or pauses, the arrow keys step a frame
 * back or on, Home and End go to the first and last. */
export async function replay(el, data) {
  const scene = data.scene;
  const arrays = {
    springs: await inflate(data.springs, Int32Array),
    rest: await inflate(data.rest, Float32Array),
    fixed: await inflate(data.fixed, Uint8Array),
  };
  const size = arrays.fixed.length * scene.dim, count = data.times.length;
  const frames = positionsOf(await inflate(data.frames, Uint16Array), size, data.low, data.step);
  const still = window.matchMedia?.("(prefers-reduced-motion: reduce)").matches ?? false;
  let index = 0, playing = !still, start = performance.now();
  const frameAt = (i) => frames.subarray(i * size, (i + 1) * size);
  const view = mountView(el, scene, arrays, { latest: () => frameAt(index) });
  const bar = element("div", { className: "msdlab-controls" }, view.root);
  const play = button(bar, "", "", () => setPlaying(!playing));
  const setPlaying = (on) => {
    playing = on;
    start = performance.now() - (index * 1000) / data.fps;
    play.textContent = playing ? "❚❚ pause" : "▶ play";
    play.setAttribute("aria-label", playing ? "pause the replay (space)" : "play the replay (space)");
    play.title = play.getAttribute("aria-label");
  };
  setPlaying(playing);
  const scrub = element("input", { type: "range", min: 0, max: count - 1, value: 0 }, bar);
  scrub.style.cssText = "width: 50%; vertical-align: middle";
  scrub.className = "msdlab-scrub";
  scrub.setAttribute("aria-label", "frame of the replay");
  const goTo = (i) => {
    index = Math.max(0, Math.min(count - 1, i));
    if (playing) setPlaying(false);
  };
  scrub.addEventListener("input", () => goTo(Number(scrub.value)));
  replayKeys(view.root, play, goTo, () => index, count);
  let said = -1;
  const tick = () => {
    if (playing) index = Math.floor(((performance.now() - start) * data.fps) / 1000) % count;
    scrub.value = index;
    const where = `t = ${data.times[index].toPrecision(4)} ${data.unit}`;
    view.status.textContent = `${where} · frame ${index + 1} of ${count}`;
    view.status.dataset.frame = String(index);
    if (said !== index) scrub.setAttribute("aria-valuetext", `${where}, frame ${index + 1} of ${count}`);
    said = index;
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
  return view;
}

/** The replay's keys on its region (the scrubber keeps its own arrow keys). */
function replayKeys(root, play, goTo, index, count) {
  root.tabIndex = 0;
  root.setAttribute("role", "region");
  root.setAttribute("aria-label", "replay. Keys: space plays or pauses, the left and right "
    + "arrow keys step a frame, Home and End go to the first and last frame");
  root.addEventListener("keydown", (event) => {
    const target = event.target;
    if (target.tagName === "INPUT" || (target.tagName === "BUTTON" && event.key === " ")) return;
    const moves = { ArrowLeft: () => goTo(index() - 1), ArrowRight: () => goTo(index() + 1),
      Home: () => goTo(0), End: () => goTo(count - 1), " ": () => play.click() };
    const shifted = event.shiftKey && target.tagName === "CANVAS"; // the canvas turns the view
    if (!moves[event.key] || shifted || event.ctrlKey || event.metaKey || event.altKey) return;
    event.preventDefault();
    moves[event.key]();
  });
}

export default { render };
