// Opens fbd's viewer.html in headless Chromium (Debian's /usr/bin/chromium,
// driven by playwright-core) and checks what it draws against the run's
// trajectory.csv. Run by scripts/test-browser.sh, which makes the runs:
//
//   FBD_PLANAR_DIR   output folder of `fbd run` (the default experiment)
//   FBD_HEXAPOD_DIR  output folder of a hexapod run
//   FBD_DYNAMIC_DIR  output folder of a dynamic (3D FBD) hexapod run
//   FBD_ROBOT_DIR    output folder of an imported robot's run, with its
//                    viewer.html (`fbd view`)
//   FBD_SCREENSHOT_DIR  where viewer.png / viewer_hexapod.png /
//                       viewer_hexapod_walk.png / viewer_robot.png are saved
//                       (optional)
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, existsSync } from 'node:fs';
import { join, basename } from 'node:path';
import { pathToFileURL } from 'node:url';
import { chromium } from 'playwright-core';

const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
// No network on the test machines: Chromium's background connections are
// switched off; WebGL runs on SwiftShader (software).
const ARGS = [
  '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--enable-unsafe-swiftshader',
];
const VIEWPORT = { width: 1280, height: 860 };

/** A CSV file (no quoting in fbd's files) as { header, rows, col(name) }. */
function readCsv(file) {
  const lines = readFileSync(file, 'utf8').trim().split('\n');
  const header = lines[0].split(',');
  const rows = lines.slice(1).map((l) => l.split(','));
  const index = new Map(header.map((h, i) => [h, i]));
  const col = (name) => {
    assert.ok(index.has(name), `${file}: no column ${name}`);
    return index.get(name);
  };
  return { header, rows, col };
}

let browser;
before(async () => {
  assert.ok(existsSync(CHROMIUM), `${CHROMIUM} is missing: apt-get install chromium`);
  browser = await chromium.launch({ executablePath: CHROMIUM, args: ARGS });
});
after(async () => {
  await browser?.close();
});

/** Opens dir/viewer.html; every request other than the page is recorded
 *  and refused, every console error and page error recorded. */
async function open(dir, viewport = VIEWPORT) {
  const file = join(dir, 'viewer.html');
  assert.ok(existsSync(file), `${file} was not written`);
  const url = pathToFileURL(file).href;
  const context = await browser.newContext({ viewport, offline: true });
  const page = await context.newPage();
  const requests = [];
  const errors = [];
  await context.route('**/*', (route) => {
    const u = route.request().url();
    if (u === url) return route.continue();
    requests.push(u);
    return route.abort();
  });
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(e.message));
  // (a long run's page takes a while on software WebGL, beside another)
  await page.goto(url, { timeout: 120000 });
  await page.waitForFunction(() => window.fbdViewer !== undefined, null, { timeout: 30000 });
  return { page, context, requests, errors };
}

/** Keeps the 3D view's pixels (read back from the WebGL canvas) in the
 *  page under `name`; the comparisons below run in the page too. */
async function snap(page, name) {
  await page.evaluate((name) => {
    const c = document.getElementById('canvas3d');
    const g = Object.assign(document.createElement('canvas'), { width: c.width, height: c.height }).getContext('2d', { willReadFrequently: true });
    g.drawImage(c, 0, 0);
    window.__snaps = window.__snaps || {};
    window.__snaps[name] = { img: g.getImageData(0, 0, c.width, c.height), ratio: c.width / c.clientWidth };
  }, name);
}

/** Share of pixels that differ between two snaps. */
function difference(page, a, b) {
  return page.evaluate(([a, b]) => {
    const x = window.__snaps[a].img, y = window.__snaps[b].img;
    let n = 0;
    for (let i = 0; i < x.data.length; i += 4) {
      if (Math.abs(x.data[i] - y.data[i]) + Math.abs(x.data[i + 1] - y.data[i + 1]) + Math.abs(x.data[i + 2] - y.data[i + 2]) > 30) n++;
    }
    return n / (x.width * x.height);
  }, [a, b]);
}

/** Darkest luma in a 7×7 square around each CSS pixel of `points`. */
function darkest(page, name, points) {
  return page.evaluate(([name, points]) => {
    const { img, ratio } = window.__snaps[name];
    return points.map((p) => {
      let min = 255;
      const cx = Math.round(p.x * ratio), cy = Math.round(p.y * ratio);
      for (let j = cy - 3; j <= cy + 3; j++) {
        for (let i = cx - 3; i <= cx + 3; i++) {
          if (i < 0 || j < 0 || i >= img.width || j >= img.height) continue;
          const k = 4 * (j * img.width + i);
          min = Math.min(min, 0.299 * img.data[k] + 0.587 * img.data[k + 1] + 0.114 * img.data[k + 2]);
        }
      }
      return min;
    });
  }, [name, points]);
}

const seek = (page, i) => page.evaluate((i) => {
  window.fbdViewer.seek(i);
  return { frame: window.fbdViewer.frame, row: window.fbdViewer.row[i], world: window.fbdViewer.worldPoints(), screen: window.fbdViewer.screenPoints() };
}, i);

/** The checks common to both models; `expect(row)` gives the CSV position
 *  of named points, `dark` the names of points drawn in the dark body colour. */
async function checkRun(t, dir, { expect, dark, screenshot, shotFrame }) {
  const csv = readCsv(join(dir, 'trajectory.csv'));
  const { page, context, requests, errors } = await open(dir);
  try {
    const v = await page.evaluate(() => ({ n: window.fbdViewer.frameCount, rows: window.fbdViewer.rows, row: window.fbdViewer.row }));

    await t.test('frame count equals the rows of trajectory.csv', () => {
      assert.equal(v.rows, csv.rows.length);
      if (csv.rows.length <= 2000) {
        assert.equal(v.n, csv.rows.length);
        assert.deepEqual(v.row, csv.rows.map((_, i) => i));
      } else {
        assert.ok(v.n <= 2000, `${v.n} frames`);
      }
    });

    const frames = [...new Set([0, Math.floor(v.n / 3), Math.floor(2 * v.n / 3), v.n - 1])];
    for (const i of frames) {
      await t.test(`frame ${i}: points drawn where trajectory.csv puts them`, async () => {
        const s = await seek(page, i);
        assert.equal(s.frame, i);
        const row = csv.rows[s.row];
        const world = new Map(s.world.map((p) => [p.name, p]));
        for (const [name, want] of Object.entries(expect(row, csv))) {
          const got = world.get(name);
          assert.ok(got, `no drawn point ${name}`);
          ['x', 'y', 'z'].forEach((k, a) => {
            if (want[a] === undefined) return;
            assert.ok(Math.abs(got[k] - want[a]) < 2e-6, `frame ${i} ${name}.${k}: drawn ${got[k]}, trajectory.csv ${want[a]}`);
          });
        }
        // On screen: inside the view, and the dark links' points are drawn
        // (a dark pixel next to each).
        const box = await page.evaluate(() => { const c = document.getElementById('canvas3d'); return { w: c.clientWidth, h: c.clientHeight }; });
        for (const p of s.screen) {
          assert.ok(p.x >= 0 && p.x <= box.w && p.y >= 0 && p.y <= box.h, `frame ${i} ${p.name} off screen at (${p.x}, ${p.y})`);
        }
        // (without the leg numbers and the heading arrow, drawn over the links)
        await page.evaluate(() => window.fbdViewer.annotations(false));
        await snap(page, 'frame');
        await page.evaluate(() => window.fbdViewer.annotations(true));
        // (each dark point not hidden behind another drawn point's sphere
        // nearer to the camera: one that reaches the 7×7 pixels around it)
        const hidden = (p) => s.screen.some((q) => !dark.includes(q.name) && q.depth < p.depth && Math.hypot(q.x - p.x, q.y - p.y) < q.r + 5);
        const marked = s.screen.filter((p) => dark.includes(p.name) && !hidden(p));
        assert.ok(marked.length >= Math.min(dark.length, 3), `frame ${i}: only ${marked.length} of ${dark.join(', ')} in view`);
        const luma = await darkest(page, 'frame', marked);
        marked.forEach((p, k) => {
          assert.ok(luma[k] < 110, `frame ${i}: nothing dark drawn at ${p.name} (${p.x.toFixed(1)}, ${p.y.toFixed(1)}), darkest luma ${luma[k].toFixed(0)}`);
        });
      });
    }

    await t.test('seeking changes the picture', async () => {
      await seek(page, 0);
      await snap(page, 'first');
      await seek(page, v.n - 1);
      await snap(page, 'last');
      const d = await difference(page, 'first', 'last');
      assert.ok(d > 0.005, `only ${(100 * d).toFixed(3)} % of the pixels changed`);
    });

    await t.test('play advances the frames and changes the picture', async () => {
      await seek(page, 0);
      await snap(page, 'before');
      await page.click('#play');
      await page.waitForFunction(() => window.fbdViewer.frame >= 10, null, { timeout: 20000 });
      // Pause (the run may already have played to its end on a busy machine).
      const state = await page.evaluate(() => {
        window.fbdViewer.pause();
        return { frame: window.fbdViewer.frame, playing: window.fbdViewer.playing };
      });
      assert.equal(state.playing, false);
      assert.ok(state.frame >= 10);
      const still = await page.evaluate(() => new Promise((done) => {
        const f = window.fbdViewer.frame;
        setTimeout(() => done(window.fbdViewer.frame === f), 300);
      }));
      assert.ok(still, 'the frame changed while paused');
      await snap(page, 'after');
      assert.ok(await difference(page, 'before', 'after') > 0.001, 'the picture did not change while playing');
    });

    await t.test('clicking a time-series panel seeks there', async () => {
      await seek(page, 0);
      const panel = page.locator('.panel canvas').first();
      const box = await panel.boundingBox();
      // Plot area: 52 px from the left, 8 px from the right (viewer.js).
      const x = 52 + 0.75 * (box.width - 60);
      await panel.click({ position: { x, y: box.height / 2 } });
      const got = await page.evaluate(() => ({ f: window.fbdViewer.frame, t: window.fbdViewer.times }));
      const want = got.t[0] + 0.75 * (got.t[got.t.length - 1] - got.t[0]);
      assert.ok(Math.abs(got.t[got.f] - want) <= 0.02 * (got.t[got.t.length - 1] - got.t[0]) + 1e-9, `seeked to t = ${got.t[got.f]}, expected about ${want}`);
    });

    if (await page.isVisible('#show-joint')) {
      await t.test('the joint-force arrows toggle', async () => {
        await seek(page, v.n - 1);
        await snap(page, 'without');
        await page.check('#show-joint');
        await snap(page, 'with');
        await page.uncheck('#show-joint');
        const d = await difference(page, 'without', 'with');
        // (joint forces are clipped to the longest arrow: a few pixels)
        assert.ok(d > 0.00005, `the joint-force arrows changed only ${d}`);
      });
    }

    await t.test('the header counts every row of events.csv', async () => {
      const rows = readCsv(join(dir, 'events.csv')).rows.length;
      const info = await page.textContent('#info');
      assert.ok(info.includes(`${rows} events (events.csv`), `header "${info}", events.csv ${rows} rows`);
    });

    await t.test('the page is titled after the model, not the output folder', async () => {
      const title = await page.title();
      assert.ok(!title.includes(basename(dir)), `title "${title}" names the folder ${basename(dir)}`);
      assert.ok(/planar model|hexapod/.test(title), `title "${title}"`);
    });

    await t.test('force arrows stay inside the view at every frame (clipped, with the force written)', async () => {
      const bad = await page.evaluate(() => {
        const v = window.fbdViewer;
        const c = document.getElementById('canvas3d');
        const out = [];
        let clippedFrames = 0;
        for (let i = 0; i < v.frameCount; i++) {
          v.seek(i);
          for (const p of v.arrowTips()) if (p.x < 0 || p.y < 0 || p.x > c.clientWidth || p.y > c.clientHeight) out.push(`frame ${i}: (${p.x.toFixed(0)}, ${p.y.toFixed(0)})`);
          if (v.clipped().length) {
            clippedFrames++;
            if (!document.getElementById('overlay').textContent.includes(' N')) out.push(`frame ${i}: clipped arrows without their force`);
          }
        }
        return { out, clippedFrames };
      });
      assert.deepEqual(bad.out.slice(0, 5), []);
    });

    if (screenshot) {
      await seek(page, shotFrame(v));
      await page.screenshot({ path: screenshot, fullPage: true });
    }

    await t.test('no console error and no network request', () => {
      assert.deepEqual(errors, []);
      assert.deepEqual(requests, []);
    });
  } finally {
    await context.close();
  }
    await t.test('the page fits a 1366×768 window: view, controls and panels', async () => {
      const { page: p, context: small } = await open(dir, { width: 1366, height: 768 });
      try {
        const box = await p.evaluate(() => {
          const last = [...document.querySelectorAll('.panel')].map((e) => e.getBoundingClientRect().bottom);
          return { scroll: document.documentElement.scrollHeight, panels: Math.max(0, ...last) };
        });
        assert.ok(box.panels <= 768, `the panels end at ${box.panels} px`);
        assert.ok(box.scroll <= 768, `the page is ${box.scroll} px high`);
      } finally {
        await small.close();
      }
    });

}

const num = (row, csv, name) => Number(row[csv.col(name)]);
const shots = process.env.FBD_SCREENSHOT_DIR;

test('planar run (the paper\'s fall)', async (t) => {
  const dir = process.env.FBD_PLANAR_DIR;
  assert.ok(dir, 'FBD_PLANAR_DIR is not set (run scripts/test-browser.sh)');
  const events = readCsv(join(dir, 'events.csv'));
  await checkRun(t, dir, {
    expect: (row, csv) => ({
      body: [num(row, csv, 'rx'), num(row, csv, 'ry'), 0],
      tip3: [num(row, csv, 'tip3_x'), num(row, csv, 'tip3_y'), 0],
      tip4: [num(row, csv, 'tip4_x'), num(row, csv, 'tip4_y'), 0],
    }),
    dark: ['body'],
    screenshot: shots && join(shots, 'viewer.png'),
    // At rest on feet and hips: the weight on the contact-force arrows.
    shotFrame: (v) => v.n - 1,
  });
  await t.test('a scale bar and the axes in the side view', async () => {
    const { page, context } = await open(dir);
    try {
      const s = await page.evaluate(() => {
        const v = window.fbdViewer;
        v.seek(0);
        // Pixels per metre from two drawn points.
        const w = v.worldPoints(), sc = v.screenPoints();
        const a = w.findIndex((p) => p.name === 'tip3'), b = w.findIndex((p) => p.name === 'body');
        const perM = Math.hypot(sc[a].x - sc[b].x, sc[a].y - sc[b].y) / Math.hypot(w[a].x - w[b].x, w[a].y - w[b].y);
        return { bar: v.scaleBar(), perM, text: document.getElementById('overlay').textContent };
      });
      assert.ok(s.bar.metres > 0, 'no scale bar');
      assert.ok(Math.abs(s.bar.px - s.bar.metres * s.perM) < 0.02 * s.bar.px, `bar ${s.bar.px} px for ${s.bar.metres} m, view ${s.perM} px/m`);
      assert.ok(s.text.includes(`${s.bar.metres} m`) && s.text.includes('X') && s.text.includes('Y'), s.text);
    } finally {
      await context.close();
    }
  });
  await t.test('every contact event is marked', async () => {
    // The events are read back in the test's own browser page below.
    const { page, context } = await open(dir);
    try {
      const marks = await page.evaluate(() => window.fbdViewer.events.map((e) => e.t));
      // Contact events only (not a joint reaching a limit, nor substeps).
      const contact = events.rows.filter((r) => /^ST[123]$/.test(r[events.col('from')]));
      assert.deepEqual(marks, contact.map((r) => Number(r[events.col('t')])));
    } finally {
      await context.close();
    }
  });
});

test('hexapod run', async (t) => {
  const dir = process.env.FBD_HEXAPOD_DIR;
  assert.ok(dir, 'FBD_HEXAPOD_DIR is not set (run scripts/test-browser.sh)');
  await checkRun(t, dir, {
    expect: (row, csv) => {
      const e = { base: [num(row, csv, 'rx'), num(row, csv, 'ry'), num(row, csv, 'rz')] };
      for (let n = 1; n <= 6; n++) e[`tip${n}`] = ['x', 'y', 'z'].map((a) => num(row, csv, `foot${n}_${a}`));
      return e;
    },
    // The knees (the joints θ3, drawn in the body's colour).
    dark: [1, 2, 3, 4, 5, 6].map((n) => `theta3_${n}`),
    screenshot: shots && join(shots, 'viewer_hexapod.png'),
    shotFrame: (v) => Math.floor(v.n / 3),
  });
  await checkLegsAndHeading(t, dir);
  await checkCapsules(t, dir);
});

/** Leg numbers beside the hips (the joints θ1) and a heading arrow
 *  towards the body's front vertex (corner2, between legs 1 and 2). */
async function checkLegsAndHeading(t, dir) {
  const { page, context } = await open(dir);
  try {
    await t.test('leg numbers beside the hips, a heading arrow along the body\'s front', async () => {
      const n = await page.evaluate(() => window.fbdViewer.frameCount);
      for (const i of [0, Math.floor(n / 2), n - 1]) {
        const s = await page.evaluate((i) => {
          const v = window.fbdViewer;
          v.seek(i);
          return { labels: v.legLabels(), screen: v.screenPoints(), world: v.worldPoints(), heading: v.heading() };
        }, i);
        const hips = s.screen.filter((p) => /^theta1_\d$/.test(p.name));
        assert.equal(s.labels.length, hips.length, `frame ${i}: ${s.labels.length} labels for ${hips.length} hips`);
        for (const l of s.labels) {
          assert.equal(l.point, `theta1_${l.text}`, `label ${l.text} beside ${l.point}`);
          const h = hips.find((p) => p.name === l.point);
          assert.ok(Math.hypot(l.x - h.x, l.y - h.y) < 60, `frame ${i}: label ${l.text} ${Math.hypot(l.x - h.x, l.y - h.y).toFixed(0)} px from its hip`);
        }
        const w = new Map(s.world.map((p) => [p.name, p]));
        const b = w.get('base'), c = w.get('corner2');
        const d = [c.x - b.x, c.y - b.y, c.z - b.z];
        const len = Math.hypot(...d);
        assert.ok(s.heading, 'no heading arrow');
        const dot = (d[0] * s.heading[0] + d[1] * s.heading[1] + d[2] * s.heading[2]) / len;
        assert.ok(dot > 0.9999, `frame ${i}: heading arrow off the body's front (cos ${dot})`);
      }
    });
  } finally {
    await context.close();
  }
}

/** The one 3D scene of every robot: a `robot` scene whose capsules (their
 *  radius, between the drawn points) are all drawn on screen, at the first,
 *  middle and last frames. */
async function checkCapsules(t, dir) {
  const { page, context, errors } = await open(dir);
  try {
    const v = await page.evaluate(() => ({ n: window.fbdViewer.frameCount, model: window.fbdViewer.model, radius: window.fbdViewer.radius, lines: window.fbdViewer.lines.length }));
    await t.test('drawn by the one 3D scene: a robot scene of capsules', () => {
      assert.equal(v.model, 'robot');
      assert.ok(v.lines > 0, 'no capsules');
      assert.ok(v.radius > 0, `capsule radius ${v.radius}`);
    });
    for (const i of [...new Set([0, Math.floor(v.n / 2), v.n - 1])]) {
      await t.test(`frame ${i}: every capsule drawn on screen, at its points`, async () => {
        const s = await page.evaluate((i) => {
          const w = window.fbdViewer;
          w.seek(i);
          w.annotations(false);
          return { world: w.worldPoints(), screen: w.screenPoints(), lines: w.lines, capsules: w.capsules() };
        }, i);
        // Each capsule runs between its two drawn points.
        s.lines.forEach((l, k) => {
          for (const [end, p] of [[0, s.world[l.a]], [1, s.world[l.b]]]) {
            const c = s.capsules[k][end];
            assert.ok(Math.hypot(c[0] - p.x, c[1] - p.y, c[2] - p.z) < 1e-9, `frame ${i}: capsule ${k} off ${p.name}`);
          }
        });
        await snap(page, 'capsules');
        await page.evaluate(() => window.fbdViewer.annotations(true));
        const mids = s.lines.map((l) => ({ x: 0.5 * (s.screen[l.a].x + s.screen[l.b].x), y: 0.5 * (s.screen[l.a].y + s.screen[l.b].y) }));
        const luma = await darkest(page, 'capsules', mids);
        luma.forEach((l, k) => {
          const { a, b } = s.lines[k];
          assert.ok(l < 230, `frame ${i}: capsule ${s.screen[a].name}–${s.screen[b].name} not drawn (lightest ${l.toFixed(0)})`);
        });
      });
    }
    await t.test('no console error', () => assert.deepEqual(errors, []));
  } finally {
    await context.close();
  }
}

test('dynamic hexapod run (3D FBD)', async (t) => {
  const dir = process.env.FBD_DYNAMIC_DIR;
  assert.ok(dir, 'FBD_DYNAMIC_DIR is not set (run scripts/test-browser.sh)');
  const csv = readCsv(join(dir, 'trajectory.csv'));
  // The model's legs: those with a state column.
  const legs = [1, 2, 3, 4, 5, 6].filter((n) => csv.header.includes(`state${n}`));
  await checkRun(t, dir, {
    expect: (row, csv) => {
      const e = { base: [num(row, csv, 'rx'), num(row, csv, 'ry'), num(row, csv, 'rz')] };
      for (const n of legs) e[`tip${n}`] = ['x', 'y', 'z'].map((a) => num(row, csv, `foot${n}_${a}`));
      return e;
    },
    // The body's corners (the knees are contact points, coloured by state).
    dark: [1, 2, 3, 4, 5, 6].map((k) => `corner${k}`),
    screenshot: shots && join(shots, 'viewer_hexapod_walk.png'),
    shotFrame: (v) => Math.floor(v.n / 3),
  });
  await checkLegsAndHeading(t, dir);
  await checkCapsules(t, dir);
  await t.test('the slope of the ground is drawn and named', async () => {
    const { page, context } = await open(dir);
    try {
      const note = await page.evaluate(() => window.fbdViewer.slopeNote);
      const text = await page.textContent('#overlay');
      assert.ok(/3\.5° slope, rising towards \+X/.test(note), `slope note "${note}"`);
      assert.ok(text.includes(note), text);
    } finally {
      await context.close();
    }
  });
  const { page, context, errors } = await open(dir);
  try {
    await t.test('every foot: its state and its ground force as trajectory.csv has them', async () => {
      const n = await page.evaluate(() => window.fbdViewer.frameCount);
      assert.ok(await page.evaluate(() => window.fbdViewer.dynamic));
      let touching = 0;
      for (const i of [...new Set([0, Math.floor(n / 4), Math.floor(n / 2), Math.floor(3 * n / 4), n - 1])]) {
        const s = await page.evaluate((i) => {
          window.fbdViewer.seek(i);
          return { row: window.fbdViewer.row[i], state: window.fbdViewer.state(), fc: window.fbdViewer.contactForces(), shown: window.fbdViewer.arrowsShown() };
        }, i);
        const row = csv.rows[s.row];
        assert.equal(s.state.slice(0, legs.length), legs.map((n) => row[csv.col(`state${n}`)].slice(2)).join(''), `frame ${i}`);
        let loaded = 0;
        legs.forEach((n, k) => {
          const want = ['fx', 'fy', 'fz'].map((a) => num(row, csv, `foot${n}_${a}`));
          want.forEach((w, a) => assert.ok(Math.abs(s.fc[3 * k + a] - w) < 2e-6, `frame ${i} foot ${n} force ${a}: drawn ${s.fc[3 * k + a]}, trajectory.csv ${w}`));
          if (Math.hypot(...want) > 1) loaded++;
        });
        // Every loaded foot has its arrow (contact forces are shown by default).
        assert.ok(s.shown >= loaded, `frame ${i}: ${s.shown} arrows for ${loaded} loaded feet`);
        touching += loaded;
      }
      assert.ok(touching > 0, 'no foot carried a force in the frames checked');
    });
    await t.test('every change of a foot\'s state is marked', async () => {
      const marks = await page.evaluate(() => window.fbdViewer.events.map((e) => `${e.t} ${e.label}`));
      // The contacts in the viewer's order: the feet, then each leg's knee
      // and hip points when the model has them.
      const contacts = legs.map((n) => [`state${n}`, `leg ${n} foot`]);
      for (const n of legs) {
        for (const [p, name] of [['kneepoint', 'knee'], ['hippoint', 'hip']]) {
          if (csv.header.includes(`${p}${n}_state`)) contacts.push([`${p}${n}_state`, `leg ${n} ${name}`]);
        }
      }
      const want = [];
      for (let r = 1; r < csv.rows.length; r++) {
        for (const [column, label] of contacts) {
          const a = csv.rows[r - 1][csv.col(column)], b = csv.rows[r][csv.col(column)];
          if (a !== b) want.push(`${Number(csv.rows[r][0])} ${label} ${a}→${b}`);
        }
      }
      assert.ok(want.length > 0, 'no state change in the run');
      assert.deepEqual(marks, want);
    });
    await t.test('no console error', () => assert.deepEqual(errors, []));
  } finally {
    await context.close();
  }
});

test('imported robot run (URDF, bodies as capsules)', async (t) => {
  const dir = process.env.FBD_ROBOT_DIR;
  assert.ok(dir, 'FBD_ROBOT_DIR is not set (run scripts/test-browser.sh)');
  const csv = readCsv(join(dir, 'trajectory.csv'));
  const { page, context, requests, errors } = await open(dir);
  try {
    const v = await page.evaluate(() => {
      const w = window.fbdViewer;
      return { n: w.frameCount, rows: w.rows, row: w.row, model: w.model, radius: w.radius, lines: w.lines.length };
    });
    await t.test('a robot scene of every row of trajectory.csv', () => {
      assert.equal(v.model, 'robot');
      assert.equal(v.rows, csv.rows.length);
      assert.ok(csv.rows.length <= 2000);
      assert.equal(v.n, csv.rows.length);
      assert.deepEqual(v.row, csv.rows.map((_, i) => i));
      assert.ok(v.lines > 0, 'no capsules');
      assert.ok(v.radius > 0, `capsule radius ${v.radius}`);
    });
    const frames = [...new Set([0, Math.floor(v.n / 2), v.n - 1])];
    for (const i of frames) {
      await t.test(`frame ${i}: the base where trajectory.csv puts it, every capsule drawn on screen`, async () => {
        const s = await page.evaluate((i) => {
          const w = window.fbdViewer;
          w.seek(i);
          return { row: w.row[i], world: w.worldPoints(), screen: w.screenPoints(), lines: w.lines };
        }, i);
        const row = csv.rows[s.row];
        const base = s.world.find((p) => p.name === 'base');
        assert.ok(base, 'no base point');
        ['rx', 'ry', 'rz'].forEach((c, a) => {
          const got = base[['x', 'y', 'z'][a]];
          const want = Number(row[csv.col(c)]);
          assert.ok(Math.abs(got - want) < 2e-6, `frame ${i} base ${c}: drawn ${got}, trajectory.csv ${want}`);
        });
        const box = await page.evaluate(() => { const c = document.getElementById('canvas3d'); return { w: c.clientWidth, h: c.clientHeight }; });
        for (const p of s.screen) {
          assert.ok(p.x >= 0 && p.x <= box.w && p.y >= 0 && p.y <= box.h, `frame ${i} ${p.name} off screen at (${p.x}, ${p.y})`);
        }
        await snap(page, 'robot');
        // The middle of every capsule on screen is drawn (not the white
        // background), and the base's dark sphere is there.
        const mids = s.lines.map((l) => ({ x: 0.5 * (s.screen[l.a].x + s.screen[l.b].x), y: 0.5 * (s.screen[l.a].y + s.screen[l.b].y) }));
        const luma = await darkest(page, 'robot', mids);
        luma.forEach((l, k) => {
          const { a, b } = s.lines[k];
          assert.ok(l < 230, `frame ${i}: capsule ${s.screen[a].name}–${s.screen[b].name} not drawn (lightest ${l.toFixed(0)})`);
        });
        const [dark] = await darkest(page, 'robot', [s.screen.find((p) => p.name === 'base')]);
        assert.ok(dark < 110, `frame ${i}: nothing dark at the base (luma ${dark.toFixed(0)})`);
        // Non-background pixels over the whole view.
        const drawn = await page.evaluate(() => {
          const { img } = window.__snaps.robot;
          let n = 0;
          for (let k = 0; k < img.data.length; k += 4) if (img.data[k] + img.data[k + 1] + img.data[k + 2] < 3 * 245) n++;
          return n / (img.width * img.height);
        });
        assert.ok(drawn > 0.005, `only ${(100 * drawn).toFixed(3)} % of the view drawn`);
      });
    }
    await t.test('seeking changes the picture', async () => {
      await seek(page, 0);
      await snap(page, 'first');
      await seek(page, v.n - 1);
      await snap(page, 'last');
      const d = await difference(page, 'first', 'last');
      assert.ok(d > 0.005, `only ${(100 * d).toFixed(3)} % of the pixels changed`);
    });
    // A run on the ground: each contact point's state and ground force as
    // trajectory.csv has them (a flight has no such columns).
    const names = await page.evaluate(() => window.fbdViewer.contactNames);
    if (names.length && csv.header.includes(`${names[0]}_state`)) {
      await t.test('every contact point: its state and ground force as trajectory.csv has them', async () => {
        for (const i of frames) {
          const s = await page.evaluate((i) => {
            window.fbdViewer.seek(i);
            return { row: window.fbdViewer.row[i], state: window.fbdViewer.state(), fc: window.fbdViewer.contactForces() };
          }, i);
          const row = csv.rows[s.row];
          assert.equal(s.state, names.map((c) => row[csv.col(`${c}_state`)].slice(2)).join(''), `frame ${i}`);
          names.forEach((c, k) => ['fx', 'fy', 'fz'].forEach((a, j) => {
            const want = num(row, csv, `${c}_${a}`);
            assert.ok(Math.abs(s.fc[3 * k + j] - want) < 2e-6, `frame ${i} ${c}_${a}: drawn ${s.fc[3 * k + j]}, trajectory.csv ${want}`);
          }));
        }
      });
    }
    await t.test('the page is titled after the robot, with its panels', async () => {
      const title = await page.title();
      assert.ok(/robot/.test(title) && !title.includes(basename(dir)), `title "${title}"`);
      const panels = await page.evaluate(() => [...document.querySelectorAll('.panel h2')].map((h) => h.textContent));
      assert.ok(panels.includes('Joint angles (°)'), panels.join(', '));
    });
    if (shots) {
      await seek(page, Math.floor(v.n / 2));
      await page.screenshot({ path: join(shots, 'viewer_robot.png'), fullPage: true });
    }
    await t.test('no console error and no network request', () => {
      assert.deepEqual(errors, []);
      assert.deepEqual(requests, []);
    });
  } finally {
    await context.close();
  }
});
