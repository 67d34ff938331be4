#!/usr/bin/python3
"""The page of `msm report`: DIR/index.html and its charts from results.json.

    report_page.py RESULTS.json --schema SCHEMA --out DIR            one run
    report_page.py A/results.json B/results.json --schema S --out DIR two runs side by side

Each results.json is validated against the schema first. The page is static and self-contained
(styles and script inline, no network); the images stay beside their results.json, the charts
(matplotlib, SVG) go to DIR/charts/. Run by Debian's Python (/usr/bin/python3), which has matplotlib.
"""
import argparse
import html
import json
import os
import sys

try:
    import matplotlib
except ImportError:
    sys.exit(f"report_page: {sys.executable} has no matplotlib: run Debian's /usr/bin/python3 (python3-matplotlib; "
             "scripts/bootstrap.sh installs it), or name another Python in MSM_PYTHON")

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import LinearSegmentedColormap  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import report_schema  # noqa: E402

# The table's figures: (heading, key of a technique's "metrics", how it is shown).
METRIC_COLUMNS = [
    ("MAE", "mae", "{:.5f}"),
    ("light leaking", "light_leaking", "{:.5f}"),
    ("over-darkening", "over_darkening", "{:.5f}"),
    ("off > 3%", "share_above_3pct", "{:.2%}"),
]
# Metrics that differ by more than this between two runs are a difference (the renders of one
# device are deterministic; time is not, and is shown but never counted as one).
METRIC_TOLERANCE = 1e-7

# The error maps' colours (msm/image/metrics.h error_image): blue = darker than the truth,
# white = equal, red = brighter (light leaking); linear in display values.
ERROR_MAP = LinearSegmentedColormap.from_list("msm_error", [(0, 0, 1), (1, 1, 1), (1, 0, 0)])

plt.rcParams.update({"svg.hashsalt": "msm-report", "font.size": 9, "axes.titlesize": 9})

STYLE = """
body{font-family:system-ui,sans-serif;margin:1.5em;color:#222;max-width:1400px}
h1{font-size:1.5em}h2{font-size:1.2em;margin-top:2em;border-bottom:1px solid #ccc}
.meta{font-size:.85em;color:#555}.meta code{font-size:.95em}
.grid{display:flex;flex-wrap:wrap;gap:8px}
figure{margin:0;font-size:.8em}figure img{display:block;image-rendering:pixelated;width:256px;height:auto}
.frame{position:relative;display:inline-block}
.inset-box{position:absolute;border:2px solid #ff0;box-sizing:border-box;cursor:zoom-in}
.inset-box span{position:absolute;top:0;left:0;background:#ff0;color:#000;font-size:10px;padding:0 2px}
table{border-collapse:collapse;margin:1em 0;font-size:.85em}
th,td{border:1px solid #ccc;padding:2px 6px;text-align:right}th{background:#eee;cursor:pointer;user-select:none}
td:first-child,th:first-child{text-align:left}
th[aria-sort=ascending]::after{content:" \\25B2"}th[aria-sort=descending]::after{content:" \\25BC"}
tr.differs td{background:#ffe9a8}td.changed{font-weight:bold;color:#a00}
.legend img{height:60px}.charts img{max-width:100%}
button.inset{cursor:zoom-in;padding:0;border:2px solid #ff0;background:none;margin-right:4px}
button.inset img{display:block;height:48px;image-rendering:pixelated}
dialog{max-width:95vw}dialog .grid figure img{width:auto;height:200px}
.summary{background:#f6f6f6;padding:.5em 1em;border-left:4px solid #888}
"""

SCRIPT = """
function cellValue(row, i) {
  const cell = row.cells[i];
  const v = cell.dataset.value;
  return v === undefined ? cell.textContent : parseFloat(v);
}
document.querySelectorAll('table.sortable th').forEach((th, i) => {
  th.addEventListener('click', () => {
    const table = th.closest('table');
    const body = table.tBodies[0];
    const ascending = th.getAttribute('aria-sort') !== 'ascending';
    table.querySelectorAll('th').forEach(h => h.removeAttribute('aria-sort'));
    th.setAttribute('aria-sort', ascending ? 'ascending' : 'descending');
    const column = Array.prototype.indexOf.call(th.parentNode.children, th);
    const rows = Array.from(body.rows);
    rows.sort((a, b) => {
      const x = cellValue(a, column), y = cellValue(b, column);
      const order = (typeof x === 'number' && typeof y === 'number') ? x - y : String(x).localeCompare(String(y));
      return ascending ? order : -order;
    });
    rows.forEach(r => body.appendChild(r));
  });
});
document.querySelectorAll('[data-inset]').forEach(el => {
  el.addEventListener('click', event => {
    event.preventDefault();
    document.getElementById(el.dataset.inset).showModal();
  });
});
document.querySelectorAll('dialog button.close').forEach(b => b.addEventListener('click', () => b.closest('dialog').close()));
"""


def esc(text):
    return html.escape(str(text), quote=True)


def load(path, schema):
    problems = report_schema.validate_file(schema, path)
    if problems:
        for p in problems[:20]:
            print(f"report_page: {path}: {p}", file=sys.stderr)
        sys.exit(f"report_page: {path} is not valid against {schema}")
    with open(path) as f:
        return json.load(f)


def device_name(run):
    return run["device"]["name"]


def save(fig, out, name):
    os.makedirs(os.path.join(out, "charts"), exist_ok=True)
    fig.savefig(os.path.join(out, "charts", name), metadata={"Date": None})
    plt.close(fig)
    return "charts/" + name


def passes_of(row):
    """Every pass any technique of the row ran, in the order they first appear."""
    names = []
    for t in row["techniques"]:
        names += [p for p in t["gpu_ms"] if p not in names]
    return names


def cost_chart(run, row, out):
    """GPU time per pass of each technique, stacked (the 2015 paper's timing figure, one resolution)."""
    techniques = row["techniques"]
    fig, ax = plt.subplots(figsize=(7, 0.35 * len(techniques) + 1.2))
    left = [0.0] * len(techniques)
    colours = plt.get_cmap("tab20").colors
    for k, name in enumerate(passes_of(row)):
        ms = [t["gpu_ms"].get(name, 0.0) for t in techniques]
        ax.barh([t["name"] for t in techniques], ms, left=left, label=name, color=colours[k % len(colours)])
        left = [a + b for a, b in zip(left, ms)]
    ax.invert_yaxis()
    ax.set_xlabel("GPU time per frame (ms), " + run["timing"].split(",")[0])
    ax.set_title(f"{row['id']}: {row['width']}x{row['height']}, shadow map {row['shadow_size']}²\n"
                 f"on {device_name(run)}")
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    return save(fig, out, f"{row['id']}-cost.svg")


def error_bits_chart(run, out):
    """Error against bits per texel, one series per row (the storage trade-off of the papers)."""
    fig, ax = plt.subplots(figsize=(8, 4.5))
    named = set()  # each technique named once, at its first point
    markers = "osD^v<>ph*"
    for k, row in enumerate(run["rows"]):
        xs = [t["bits_per_texel"] for t in row["techniques"]]
        ys = [max(t["metrics"]["mae"], 1e-6) for t in row["techniques"]]
        ax.scatter(xs, ys, label=row["id"], marker=markers[k % len(markers)],
                   color=plt.get_cmap("tab20").colors[k % 20])
        for t, x, y in zip(row["techniques"], xs, ys):
            if t["name"] not in named:
                ax.annotate(t["name"], (x, y), fontsize=6, xytext=(3, 2), textcoords="offset points")
                named.add(t["name"])
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("bits per texel of the shadow map")
    ax.set_ylabel("MAE against the ray-traced truth")
    ax.set_title(f"Error against storage, suite {run['suite']['name']}\non {device_name(run)}")
    ax.legend(fontsize=6, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.tight_layout()
    return save(fig, out, "error-bits.svg")


def resolution_charts(run, out):
    """GPU time per frame against the output's pixels (one shadow-map size) and against the shadow map's
    side (one output size), per technique, for every scene the suite measures at several sizes (the
    shapes of the 2015 paper's timing figure and JCGT's Fig. 20)."""
    charts = []
    groups = {}
    for row in run["rows"]:
        groups.setdefault((row["scene"], row["truth"]["effect"]), []).append(row)
    for (scene, effect), rows in groups.items():
        for axis, fixed, x_of, label in (
                ("output", "shadow_size", lambda r: r["width"] * r["height"] / 1e6, "output megapixels"),
                ("shadow-map", "width", lambda r: r["shadow_size"], "shadow map texels per side")):
            by_fixed = {}
            for r in rows:
                by_fixed.setdefault((r[fixed], r["height"] if fixed == "width" else 0), []).append(r)
            for (fixed_value, _), series in by_fixed.items():
                xs = sorted({x_of(r) for r in series})
                if len(xs) < 2:
                    continue
                series = sorted(series, key=x_of)
                fig, ax = plt.subplots(figsize=(6, 3.6))
                for t in series[0]["techniques"]:
                    points = [(x_of(r), u["gpu_ms_total"]) for r in series for u in r["techniques"]
                              if u["name"] == t["name"]]
                    ax.plot([p[0] for p in points], [p[1] for p in points], marker="o", label=t["name"])
                ax.set_xlabel(label)
                ax.set_ylabel("GPU ms per frame")
                ax.set_xscale("log", base=2)
                ax.set_yscale("log")
                held = (f"shadow map {fixed_value}²" if fixed == "shadow_size"
                        else f"{series[0]['width']}x{series[0]['height']}")
                ax.set_title(f"{scene} ({effect}): time against {axis} resolution, {held}\non {device_name(run)}")
                ax.legend(fontsize=6)
                fig.tight_layout()
                charts.append(save(fig, out, f"{scene}-{effect}-{axis}-cost.svg"))
    return charts


def legend_chart(error_range, out):
    fig, ax = plt.subplots(figsize=(5, 0.8))
    norm = matplotlib.colors.Normalize(-error_range, error_range)
    bar = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=ERROR_MAP), cax=ax, orientation="horizontal")
    bar.set_label(f"technique − truth (darker ← 0 → brighter: light leaking), saturated at ±{error_range:g}")
    fig.tight_layout()
    return save(fig, out, "error-legend.svg")


def compare_chart(a, b, row_a, row_b, out):
    """MAE and total GPU time of each technique in both runs."""
    names = [t["name"] for t in row_a["techniques"]]
    by_name = {t["name"]: t for t in row_b["techniques"]}
    fig, axes = plt.subplots(1, 2, figsize=(9, 0.35 * len(names) + 1.4))
    for ax, key, label in ((axes[0], "mae", "MAE"), (axes[1], None, "GPU ms per frame")):
        def value(t):
            return t["metrics"]["mae"] if key else t["gpu_ms_total"]
        ys = range(len(names))
        ax.barh([y - 0.2 for y in ys], [value(t) for t in row_a["techniques"]], height=0.4, label="A")
        ax.barh([y + 0.2 for y in ys], [value(by_name[n]) if n in by_name else 0 for n in names], height=0.4,
                label="B")
        ax.set_yticks(list(ys), names)
        ax.invert_yaxis()
        ax.set_xlabel(label)
        ax.legend(fontsize=7)
    fig.suptitle(f"{row_a['id']}: A on {device_name(a)},\nB on {device_name(b)}", fontsize=9)
    fig.tight_layout()
    return save(fig, out, f"{row_a['id']}-compare.svg")


def run_meta(run, label=""):
    d, b = run["device"], run["build"]
    return (f"<p class=meta>{esc(label)}Device <b>{esc(d['name'])}</b> ({esc(d['driver'])}, {esc(d['driver_info'])}, "
            f"Vulkan {esc(d['vulkan'])}); msm {esc(b['version'])} {esc(b['build_type'])}, commit "
            f"<code>{esc(b['git_commit'] or 'unknown')}</code>; suite <b>{esc(run['suite']['name'])}</b> started "
            f"{esc(run['started_utc'])}, {run['seconds']:.1f} s on {esc(run['host']['hostname'])}; "
            f"<code>{esc(run['command'])}</code>. {esc(run['timing'])}.</p>")


def image_grid(row, prefix, dialog_id):
    """The truth (inset windows outlined) and every technique's render with its error map below."""
    w, h = row["width"], row["height"]
    boxes = "".join(
        f"<a href=# class=inset-box data-inset='{dialog_id}-{k}' title='inset {k + 1}' "
        f"style='left:{100 * r['x'] / w:.3f}%;top:{100 * r['y'] / h:.3f}%;width:{100 * r['width'] / w:.3f}%;"
        f"height:{100 * r['height'] / h:.3f}%'><span>{k + 1}</span></a>"
        for k, r in enumerate(row["insets"]))
    truth = row["truth"]
    cells = [f"<figure><div class=frame><img src='{esc(prefix + truth['images']['render'])}' width={w} height={h} "
             f"alt='ray-traced truth'>{boxes}</div><figcaption>ray traced ({esc(truth['effect'])}, "
             f"{truth['samples']} spp)</figcaption></figure>"]
    for t in row["techniques"]:
        render, error = esc(prefix + t["images"]["render"]), esc(prefix + t["images"]["error"])
        cells.append(f"<figure><a href='{render}'><img src='{render}' width={w} height={h} alt='{esc(t['name'])}'></a>"
                     f"<a href='{error}'><img src='{error}' width={w} height={h} alt='{esc(t['name'])} error'></a>"
                     f"<figcaption><b>{esc(t['name'])}</b> MAE "
                     f"{t['metrics']['mae']:.4f}</figcaption></figure>")
    return "<div class=grid>" + "".join(cells) + "</div>"


def inset_dialogs(row, prefix, dialog_id):
    """One dialog per inset: the window magnified in the truth and every technique."""
    out, buttons = [], []
    for k, r in enumerate(row["insets"]):
        panels = [("ray traced", row["truth"]["images"]["insets"][k])]
        panels += [(t["name"], t["images"]["insets"][k]) for t in row["techniques"]]
        figures = "".join(f"<figure><img src='{esc(prefix + src)}' alt='{esc(name)} inset {k + 1}'>"
                          f"<figcaption>{esc(name)}</figcaption></figure>" for name, src in panels)
        out.append(f"<dialog id='{dialog_id}-{k}'><p>Inset {k + 1}: pixels {r['x']}..{r['x'] + r['width'] - 1} x "
                   f"{r['y']}..{r['y'] + r['height'] - 1}, magnified {row['inset_magnification']}x "
                   f"<button class=close>close</button></p><div class=grid>{figures}</div></dialog>")
        buttons.append(f"<button class=inset data-inset='{dialog_id}-{k}' title='open inset {k + 1}'>"
                       f"<img src='{esc(prefix + row['truth']['images']['insets'][k])}' alt='inset {k + 1}'></button>")
    lead = "<p>Where the techniques differ most (click to open): " + "".join(buttons) + "</p>" if buttons else ""
    return lead + "".join(out)


def metrics_table(row):
    passes = passes_of(row)
    head = ["technique", "bits"] + [c[0] for c in METRIC_COLUMNS] + [p + " ms" for p in passes] + ["total ms"]
    lines = ["<table class=sortable><thead><tr>" + "".join(f"<th>{esc(h)}</th>" for h in head) +
             "</tr></thead><tbody>"]
    for t in row["techniques"]:
        cells = [f"<td title='{esc(t['description'])}'>{esc(t['name'])}</td>",
                 f"<td data-value={t['bits_per_texel']}>{t['bits_per_texel']}</td>"]
        for _, key, fmt in METRIC_COLUMNS:
            v = t["metrics"][key]
            cells.append(f"<td data-value={v!r}>{fmt.format(v)}</td>")
        for p in passes:
            v = t["gpu_ms"].get(p)
            cells.append("<td data-value=-1>–</td>" if v is None else f"<td data-value={v!r}>{v:.3f}</td>")
        cells.append(f"<td data-value={t['gpu_ms_total']!r}>{t['gpu_ms_total']:.3f}</td>")
        lines.append("<tr>" + "".join(cells) + "</tr>")
    warnings = [f"<li><b>{esc(t['name'])}</b>: {esc(w)}</li>" for t in row["techniques"] for w in t["warnings"]]
    notes = "<p>The renderer warned:</p><ul class=meta>" + "".join(warnings) + "</ul>" if warnings else ""
    return "\n".join(lines) + "</tbody></table>" + notes


def test_figures_table(run):
    """The figures the test suite recorded (results.json's "tests"), one sortable table."""
    tests = run.get("tests")
    if not tests:
        return ""
    lines = ["<h2>Figures the tests assert</h2>",
             f"<p class=meta>Each figure is the value an assertion of a test checks, beside its bound; gathered by "
             f"<code>{esc(tests['command'])}</code> ({tests['seconds']:.0f} s).</p>",
             "<table class=sortable><thead><tr><th>figure</th><th>value</th><th>asserted</th><th>holds</th>"
             "<th>key</th><th>test</th></tr></thead><tbody>"]
    for r in tests["runs"]:
        for f in r["figures"]:
            value, bound = ("not finite" if v is None else f"{v:.3g}" for v in (f["value"], f["bound"]))
            lines.append(f"<tr><td>{esc(f['meaning'])}</td><td data-value={f['value'] or 0!r}>{value}</td>"
                         f"<td>{esc(f['relation'])} {bound}</td><td>{'yes' if f['holds'] else 'no'}</td>"
                         f"<td><code>{esc(f['key'])}</code></td><td>{esc(f['test'])}</td></tr>")
    return "\n".join(lines) + "</tbody></table>"


def row_title(row):
    truth = row["truth"]
    lights = f", the probe cut into {truth['probe_lights']} lights" if truth["effect"] == "environment" else ""
    return (f"{esc(row['scene'])}: {esc(truth['effect'])} shadows, {row['width']}x{row['height']}, shadow map "
            f"{row['shadow_size']}²{lights}")


def page(title, body):
    return (f"<!DOCTYPE html><html lang=en><head><meta charset=utf-8><title>{esc(title)}</title>"
            f"<style>{STYLE}</style></head><body><h1>{esc(title)}</h1>{body}<script>{SCRIPT}</script></body></html>\n")


def single_page(run, out, prefix):
    parts = [run_meta(run)]
    legend = legend_chart(run["rows"][0]["error_range"], out)
    for i, row in enumerate(run["rows"]):
        dialog_id = f"inset-{i}"
        parts.append(f"<section id='{esc(row['id'])}'><h2>{row_title(row)}</h2>"
                     f"<p class=meta>Errors in the {esc(row['truth']['signal'])}, against the ray tracer "
                     f"({row['truth']['seconds']:.1f} s).</p>")
        parts.append(image_grid(row, prefix, dialog_id))
        parts.append(f"<p class=legend><img src='{legend}' alt='error colour legend'></p>")
        parts.append(inset_dialogs(row, prefix, dialog_id))
        parts.append(metrics_table(row))
        parts.append(f"<p class=charts><img src='{cost_chart(run, row, out)}' alt='GPU time per pass'></p></section>")
    charts = resolution_charts(run, out)
    if charts:
        parts.append("<h2>Cost against resolution</h2><p class=charts>" +
                     "".join(f"<img src='{c}' alt='time against resolution'>" for c in charts) + "</p>")
    parts.append(f"<h2>Error against bits per texel</h2><p class=charts><img src='{error_bits_chart(run, out)}' "
                 "alt='error against bits per texel'></p>")
    parts.append(test_figures_table(run))
    return page(f"msm report: suite {run['suite']['name']} on {device_name(run)}", "\n".join(parts))


def technique_differences(ta, tb):
    """The keys in which two runs of a technique differ (parameters, settings, metrics); time is not one."""
    keys = []
    if ta["parameters"] != tb["parameters"]:
        keys.append("parameters")
    if ta["settings"] != tb["settings"]:
        keys.append("settings")
    for key, value in ta["metrics"].items():
        if key != "pixels" and abs(value - tb["metrics"][key]) > METRIC_TOLERANCE:
            keys.append(key)
    return keys


def compare_table(row_a, row_b):
    by_name = {t["name"]: t for t in row_b["techniques"]}
    head = ["technique", "parameters A", "parameters B"]
    for h, _, _ in METRIC_COLUMNS:
        head += [f"{h} A", f"{h} B"]
    head += ["ms A", "ms B", "B / A time"]
    lines = ["<table class=sortable><thead><tr>" + "".join(f"<th>{esc(h)}</th>" for h in head) +
             "</tr></thead><tbody>"]
    differing = []
    for ta in row_a["techniques"]:
        tb = by_name.get(ta["name"])
        if tb is None:
            lines.append(f"<tr class=differs data-differs='{esc(row_a['id'])}/{esc(ta['name'])}'>"
                         f"<td>{esc(ta['name'])}</td><td colspan={len(head) - 1}>only in A</td></tr>")
            differing.append(f"{row_a['id']}/{ta['name']}")
            continue
        diff = technique_differences(ta, tb)

        def params(t):
            return ", ".join(f"{k}={v}" for k, v in t["parameters"].items()) or "–"
        pclass = " class=changed" if "parameters" in diff else ""
        cells = [f"<td>{esc(ta['name'])}</td>", f"<td{pclass}>{esc(params(ta))}</td>",
                 f"<td{pclass}>{esc(params(tb))}</td>"]
        for _, key, fmt in METRIC_COLUMNS:
            mark = " class=changed" if key in diff else ""
            for t in (ta, tb):
                v = t["metrics"][key]
                cells.append(f"<td{mark} data-value={v!r}>{fmt.format(v)}</td>")
        ratio = tb["gpu_ms_total"] / ta["gpu_ms_total"] if ta["gpu_ms_total"] > 0 else float("nan")
        cells += [f"<td data-value={ta['gpu_ms_total']!r}>{ta['gpu_ms_total']:.3f}</td>",
                  f"<td data-value={tb['gpu_ms_total']!r}>{tb['gpu_ms_total']:.3f}</td>",
                  f"<td data-value={ratio!r}>{ratio:.2f}</td>"]
        attrs = f" class=differs data-differs='{esc(row_a['id'])}/{esc(ta['name'])}'" if diff else ""
        if diff:
            differing.append(f"{row_a['id']}/{ta['name']}")
        lines.append(f"<tr{attrs}>" + "".join(cells) + "</tr>")
    for name in by_name:
        if name not in {t["name"] for t in row_a["techniques"]}:
            lines.append(f"<tr class=differs data-differs='{esc(row_a['id'])}/{esc(name)}'><td>{esc(name)}</td>"
                         f"<td colspan={len(head) - 1}>only in B</td></tr>")
            differing.append(f"{row_a['id']}/{name}")
    return "\n".join(lines) + "</tbody></table>", differing


def compare_page(a, b, out, prefix_a, prefix_b):
    parts = [run_meta(a, "A: "), run_meta(b, "B: ")]
    rows_b = {row["id"]: row for row in b["rows"]}
    sections, differing = [], []
    for i, row_a in enumerate(a["rows"]):
        row_b = rows_b.get(row_a["id"])
        if row_b is None:
            sections.append(f"<section><h2>{row_title(row_a)}</h2><p>Only in A.</p></section>")
            differing.append(row_a["id"])
            continue
        table, diff = compare_table(row_a, row_b)
        differing += diff
        sections.append(f"<section id='{esc(row_a['id'])}'><h2>{row_title(row_a)}</h2>")
        sections.append(table)
        sections.append(f"<p class=charts><img src='{compare_chart(a, b, row_a, row_b, out)}' "
                        "alt='A against B'></p>")
        sections.append("<h3>A</h3>" + image_grid(row_a, prefix_a, f"a-inset-{i}") +
                        inset_dialogs(row_a, prefix_a, f"a-inset-{i}"))
        sections.append("<h3>B</h3>" + image_grid(row_b, prefix_b, f"b-inset-{i}") +
                        inset_dialogs(row_b, prefix_b, f"b-inset-{i}") + "</section>")
    for row_id in rows_b:
        if row_id not in {row["id"] for row in a["rows"]}:
            sections.append(f"<section><h2>{esc(row_id)}</h2><p>Only in B.</p></section>")
            differing.append(row_id)
    legend = legend_chart(a["rows"][0]["error_range"], out)
    summary = ("No differences: every technique has the same parameters, settings and errors in both runs "
               f"(within {METRIC_TOLERANCE:g}; time is compared, not counted)." if not differing else
               f"{len(differing)} differ (highlighted): " + ", ".join(esc(d) for d in differing) + ".")
    parts.append(f"<p class=summary id=summary data-differences={len(differing)}>{summary}</p>")
    parts.append(f"<p class=legend><img src='{legend}' alt='error colour legend'></p>")
    print(f"report_page: {len(differing)} differences" + (": " + ", ".join(differing) if differing else ""))
    return page(f"msm report: {a['suite']['name']} on {device_name(a)} (A) against {b['suite']['name']} on "
                f"{device_name(b)} (B)", "\n".join(parts + sections))


def write_atomically(path, text):
    tmp = os.path.join(os.path.dirname(path), f".{os.path.basename(path)}.tmp.{os.getpid()}")
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


def image_prefix(results_path, out):
    rel = os.path.relpath(os.path.dirname(os.path.abspath(results_path)), os.path.abspath(out))
    return "" if rel == "." else rel.replace(os.sep, "/") + "/"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", nargs="+", help="one results.json, or two to compare")
    parser.add_argument("--schema", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    if len(args.results) > 2:
        parser.error("one results.json, or two to compare")
    runs = [load(path, args.schema) for path in args.results]
    os.makedirs(args.out, exist_ok=True)
    prefixes = [image_prefix(path, args.out) for path in args.results]
    if len(runs) == 1:
        text = single_page(runs[0], args.out, prefixes[0])
    else:
        text = compare_page(runs[0], runs[1], args.out, prefixes[0], prefixes[1])
    write_atomically(os.path.join(args.out, "index.html"), text)
    print(f"report_page: wrote {os.path.join(args.out, 'index.html')}")


if __name__ == "__main__":
    main()
