// Opens traverse-viewer's page in Debian's headless chromium (driven by playwright-core, which
// downloads no browser) and checks what a person would see: a cloud, the legend of the standard,
// and points in at least two accuracy colours, read from the page's state and from the pixels of
// its WebGL canvas; then, with the page's "voxels" ticked, the same cloud as coloured voxels (in
// at least two accuracy colours, on the canvas too). Saves a screenshot of each (the voxels' beside
// the first, "-voxels" added to its name).
//
//   node page_check.mjs --url http://127.0.0.1:PORT/ --screenshot FILE [--timeout S]
//                       [--min-points N] [--cut-feed] [--watch S [--no-draw]] [--closure N]
//                       [--compare URL]
//
// Two pages are opened side by side: the page as served, which must pass, and the same page with
// its WebSocket cut (answered by a stand-in that never sends anything), which must fail: the check
// would not notice a page that shows nothing. --cut-feed checks only the cut page, as if it were
// the real one: the run then fails, as it must. Prints one JSON line last; exits 0 when the
// served page passed and the cut one failed, 1 otherwise. --watch S only keeps one served page
// open for S seconds, as an operator would (to measure what a connected browser costs the graph),
// then prints what it showed and the CPU time chromium took [s]; with --no-draw the page is a
// blank one that only reads the viewer's WebSocket (a browser on another device, as far as this
// machine is concerned: the viewer does all its work, nothing is drawn here). --closure N watches
// the key poses on screen while a run with loop closures is fed to the viewer, and passes when at
// least N key poses were seen drawn in one level's colour and later, after a better level arrived,
// in that better level's (different) colour: the colours change live where a closure shrank the
// bounds. --compare URL (a viewer there from the start) checks the page of --url (a viewer started
// late) as above and passes when it also shows what the page at URL shows, read at the same
// moment: as many points and profiles (at least 97 %), key poses (at most 3 fewer), trajectory
// poses (at least 97 %), and the same share of points per level (within 3 points of percentage).
import { chromium } from 'playwright-core';
import { mkdtempSync, readdirSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

const args = { timeout: 90, 'min-points': 1000 };
for (let i = 2; i < process.argv.length; ++i) {
  const key = process.argv[i].replace(/^--/, '');
  if (key === 'cut-feed' || key === 'no-draw') args[key] = true;
  else args[key] = process.argv[++i];
}
if (!args.url || !args.screenshot) {
  console.error('usage: node page_check.mjs --url URL --screenshot FILE [--timeout S] [--min-points N] [--cut-feed]');
  process.exit(2);
}
const minPoints = Number(args['min-points']);

// What the page shows: its state, and the pixels of the cloud alone (key poses hidden) counted
// by legend colour, with the whole map in view.
async function look(page) {
  return page.evaluate(() => {
    const s = window.viewerState;
    const out = {
      connected: s.connected, frames: s.frames, points: s.points, profiles: s.profiles,
      legend: s.legend ? s.legend.levels.map((l) => l.name) : [],
      colours: s.legend ? Object.fromEntries(s.legend.levels.map((l) => [l.name, l.rgb.join(',')])) : {},
      legendShown: document.querySelectorAll('#legend .swatch').length,
      levelCounts: s.levelCounts, annotations: s.annotations, trajectoryPoses: s.trajectoryPoses,
      processes: s.processes.length, pixels: {},
    };
    if (s.legend && window.viewer) out.pixels = window.viewer.legendPixels();
    return out;
  });
}

// The page with "voxels" ticked: how many voxels it draws per level, and the canvas's pixels per
// legend colour with the key poses hidden (the points are hidden by the toggle itself).
async function lookVoxels(page, timeoutS) {
  await page.check('#voxels');
  const deadline = Date.now() + timeoutS * 1000;
  let v;
  for (;;) {
    v = await page.evaluate(() => {
      const s = window.viewerState;
      const out = { voxels: s.voxels, levels: s.voxelLevelCounts, pixels: {}, colours: {} };
      if (!s.legend || !s.voxels) return out;
      out.pixels = window.viewer.legendPixels();
      out.colours = Object.fromEntries(s.legend.levels.map((l) => [l.name, l.rgb.join(',')]));
      return out;
    });
    if (v.voxels > 0 || Date.now() > deadline) break;
    await new Promise((r) => setTimeout(r, 500));
  }
  return v;
}

function voxelVerdict(v) {
  if (!v.voxels) return 'no voxels drawn';
  const coloured = new Set(Object.entries(v.levels)
    .filter(([name, n]) => name !== 'none' && n > 0).map(([name]) => v.colours[name]));
  if (coloured.size < 2) return `voxels in ${coloured.size} accuracy colour(s) only`;
  const drawn = Object.entries(v.pixels).filter(([, n]) => n >= 20);
  if (drawn.length < 2) return `voxel pixels in ${drawn.length} legend colour(s) only: ${JSON.stringify(v.pixels)}`;
  return null;
}

// Why what the page shows is not enough, or null when it is.
function verdict(v) {
  if (!v.connected) return 'the page has no live WebSocket';
  if (v.points < minPoints) return `${v.points} points arrived (at least ${minPoints} expected)`;
  if (v.legend.length < 2 || v.legendShown !== v.legend.length) {
    return `legend: ${v.legend.length} levels, ${v.legendShown} shown`;
  }
  // Distinct colours, not levels: every level better than the best shares its green.
  const coloured = new Set(Object.entries(v.levelCounts)
    .filter(([name, n]) => name !== 'none' && n > 0).map(([name]) => v.colours[name]));
  if (coloured.size < 2) return `points in ${coloured.size} accuracy colour(s) only`;
  const drawn = Object.entries(v.pixels).filter(([, n]) => n >= 20);
  if (drawn.length < 2) return `pixels in ${drawn.length} legend colour(s) only: ${JSON.stringify(v.pixels)}`;
  return null;
}

// Why the late page differs from the early one, or null when it shows the same.
function sameAs(late, early) {
  const short = (what, a, b, share) => (a < share * b ? `${what}: ${a} late, ${b} early` : null);
  const why = short('points', late.points, early.points, 0.97) ||
    short('profiles', late.profiles, early.profiles, 0.97) ||
    short('trajectory poses', late.trajectoryPoses, early.trajectoryPoses, 0.97) ||
    (late.annotations < early.annotations - 3
      ? `key poses: ${late.annotations} late, ${early.annotations} early` : null);
  if (why) return why;
  const share = (v, name) => (v.levelCounts[name] || 0) / Math.max(v.points, 1);
  for (const name of new Set([...Object.keys(late.levelCounts), ...Object.keys(early.levelCounts)])) {
    const a = share(late, name), b = share(early, name);
    if (Math.abs(a - b) > 0.03) {
      return `share of points at ${name}: ${(100 * a).toFixed(1)} % late, ${(100 * b).toFixed(1)} % early`;
    }
  }
  return null;
}

async function compare(context, result) {
  const late = await context.newPage(), early = await context.newPage();
  const errors = [];
  late.on('pageerror', (e) => errors.push(String(e)));
  await late.goto(args.url);
  await early.goto(args.compare);
  const deadline = Date.now() + Number(args.timeout) * 1000;
  let seen, why;
  // What both pages hold, read at once (the graph runs on, and both viewers hear it).
  const counts = (page) => page.evaluate(() => {
    const s = window.viewerState;
    return { points: s.points, profiles: s.profiles, trajectoryPoses: s.trajectoryPoses,
      annotations: s.annotations, levelCounts: s.levelCounts };
  });
  for (;;) {
    const [a, b] = await Promise.all([counts(late), counts(early)]);
    seen = { late: { ...(await look(late)), ...a }, early: b };
    why = verdict(seen.late) || sameAs(seen.late, seen.early);
    if (!why || Date.now() > deadline) break;
    await new Promise((r) => setTimeout(r, 1000));
  }
  await late.screenshot({ path: args.screenshot });
  Object.assign(result, { late_page: seen.late, early_page: seen.early, problem: why,
    page_errors: errors, screenshot: args.screenshot });
  return !why && errors.length === 0;
}

// CPU time [s] of every process whose command line names `dir` (chromium's, by its profile).
function cpuSeconds(dir) {
  const tick = 100;  // USER_HZ on Linux
  let total = 0;
  for (const pid of readdirSync('/proc').filter((p) => /^\d+$/.test(p))) {
    try {
      if (!readFileSync(`/proc/${pid}/cmdline`, 'utf8').includes(dir)) continue;
      const stat = readFileSync(`/proc/${pid}/stat`, 'utf8');
      const fields = stat.slice(stat.lastIndexOf(')') + 2).split(' ');
      total += (Number(fields[11]) + Number(fields[12])) / tick;  // utime, stime
    } catch {
      // gone meanwhile
    }
  }
  return Math.round(total * 100) / 100;
}

async function watch(context, seconds) {
  const page = await context.newPage();
  if (args['no-draw']) {
    await page.goto('about:blank');
    await page.evaluate((url) => {
      window.fed = { connected: false, frames: 0, bytes: 0 };
      const ws = new WebSocket(url.replace(/^http/, 'ws') + 'ws');
      ws.binaryType = 'arraybuffer';
      ws.onopen = () => { window.fed.connected = true; };
      ws.onmessage = (e) => {
        ++window.fed.frames;
        window.fed.bytes += typeof e.data === 'string' ? e.data.length : e.data.byteLength;
      };
    }, args.url);
  } else {
    await page.goto(args.url);
  }
  await new Promise((r) => setTimeout(r, seconds * 1000));
  const shown = await page.evaluate(() => {
    if (window.fed) return window.fed;
    const s = window.viewerState;
    return { connected: s.connected, frames: s.frames, bytes: s.bytes, points: s.points, resets: s.resets };
  });
  shown.chromium_cpu_s = cpuSeconds(userDataDir);
  if (!args['no-draw']) await page.screenshot({ path: args.screenshot });
  return shown;
}

// The key poses as drawn now: level, and whether the pixel at each key pose's place has its
// level's colour (a neighbour drawn over it does not count).
async function keysDrawn(page) {
  return page.evaluate(() => {
    const s = window.viewerState;
    if (!s.legend || !window.viewer) return [];
    window.viewer.fit();
    const { w, h, px } = window.viewer.pixels();
    return window.viewer.keysOnScreen().map((k) => {
      const rgb = s.legend.levels[k.level].rgb;
      const i = (k.sy * w + k.sx) * 4;
      const inside = k.sx >= 0 && k.sx < w && k.sy >= 0 && k.sy < h;
      const drawn = inside && [0, 1, 2].every((c) => Math.abs(px[i + c] - rgb[c]) <= 2);
      return { id: k.id, level: k.level, rgb: rgb.join(','), drawn };
    });
  });
}

// Key poses seen drawn in one colour and later, at a better level, in another.
async function closure(context, result, needed) {
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(args.url);
  const first = new Map();  // id -> the worst level it was seen drawn at, and that colour
  const greener = new Map();  // id -> [from level, to level]
  const deadline = Date.now() + Number(args.timeout) * 1000;
  let looks = 0, seen = 0;
  while (Date.now() < deadline && greener.size < needed) {
    const keys = await keysDrawn(page);
    ++looks;
    seen = Math.max(seen, keys.length);
    for (const k of keys.filter((k) => k.drawn)) {
      const before = first.get(k.id);
      if (before && k.level < before.level && k.rgb !== before.rgb) {
        greener.set(k.id, [before.level, k.level]);
      }
      if (!before || k.level > before.level) first.set(k.id, { level: k.level, rgb: k.rgb });
    }
    await new Promise((r) => setTimeout(r, 250));
  }
  await page.screenshot({ path: args.screenshot });
  const legend = await page.evaluate(() => window.viewerState.legend?.levels.map((l) => l.name) ?? []);
  const names = (l) => legend[l] ?? String(l);
  result.closure = {
    looks, key_poses: seen, key_poses_drawn_in_their_colour: first.size,
    greener: greener.size, needed,
    examples: [...greener].slice(0, 5).map(([id, [a, b]]) => ({ id, from: names(a), to: names(b) })),
    page_errors: errors,
  };
  result.screenshot = args.screenshot;
  return greener.size >= needed && errors.length === 0;
}

const userDataDir = mkdtempSync(join(tmpdir(), 'traverse-chromium-'));
const context = await chromium.launchPersistentContext(userDataDir, {
  executablePath: '/usr/bin/chromium',
  headless: true,
  viewport: { width: 1400, height: 900 },
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
// The served page must pass within the timeout, the cut one fail.
async function check(context, result) {
  const cut = await context.newPage();
  // The stand-in server: accepts the page's WebSocket and never sends.
  await cut.routeWebSocket(/\/ws$/, () => {});
  await cut.goto(args.url);
  const served = args['cut-feed'] ? cut : await context.newPage();
  if (served !== cut) await served.goto(args.url);
  const errors = [];
  served.on('pageerror', (e) => errors.push(String(e)));
  const deadline = Date.now() + Number(args.timeout) * 1000;
  let seen, why;
  for (;;) {
    seen = await look(served);
    why = verdict(seen);
    if (!why || Date.now() > deadline) break;
    await new Promise((r) => setTimeout(r, 1000));
  }
  await served.screenshot({ path: args.screenshot });
  result.page = seen;
  result.page_problem = why;
  if (!why && served !== cut) {
    result.voxels = await lookVoxels(served, 10);
    result.voxels_problem = voxelVerdict(result.voxels);
    await served.screenshot({ path: args.screenshot.replace(/(\.png)?$/, '-voxels.png') });
    why = result.voxels_problem;
  }
  result.page_errors = errors;
  if (served !== cut) {
    result.cut_page = await look(cut);
    result.cut_page_problem = verdict(result.cut_page);
  }
  result.screenshot = args.screenshot;
  if (served === cut) return false;
  return !why && !!result.cut_page_problem && errors.length === 0;
}

const result = { url: args.url, cut_feed_only: !!args['cut-feed'] };
let ok = false;
try {
  if (args.watch) {
    result.watched = await watch(context, Number(args.watch));
    ok = result.watched.connected;
  } else if (args.compare) {
    ok = await compare(context, result);
  } else if (args.closure) {
    ok = await closure(context, result, Number(args.closure));
  } else {
    ok = await check(context, result);
  }
} finally {
  await context.close();
  rmSync(userDataDir, { recursive: true, force: true });
}
result.ok = ok;
console.log(JSON.stringify(result));
process.exit(ok ? 0 : 1);
