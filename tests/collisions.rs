//! Issue 18, end to end: the print head's collisions recomputed here from the written
//! `toolpath.csv`, independently of the planner's check (crates/collide), and the travels of the
//! written programs against the beads laid before them.

#[path = "common/readback.rs"]
mod readback;

use readback::Row as Pt;
use robot_post::machine::MachineProfile;
use robot_post::MachineKind;
use serde_json::Value;
use std::collections::{BTreeMap, HashMap};
use std::path::PathBuf;
use std::process::Command;
use std::sync::{Arc, Mutex, OnceLock};

const BIN: &str = env!("CARGO_BIN_EXE_features");

/// The default head of the issue, mm and degrees: nozzle tip radius, cone half-angle, nozzle
/// length, body radius, body top (from the tip).
const HEAD: (f64, f64, f64, f64, f64) = (0.5, 30.0, 8.0, 20.0, 60.0);

/// Depth (mm) a point must lie inside the head to count here: the planner keeps grains within
/// 0.25 mm of every bead point and counts a quarter-millimetre cell holding one when all of it
/// lies 0.1 mm inside (its centre 0.1 + 0.22 mm), so every move found here is one it reports.
const DEPTH: f64 = 0.6;

struct Out(PathBuf);

impl Drop for Out {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

struct Planned {
    plan: Value,
    points: Vec<Pt>,
    program: String,
    /// `collisions.csv`: the colliding moves left (empty when there are none).
    collisions: String,
}

/// [`plan_once`] of the fixture `name` for `machine`, made once for the whole binary: two
/// tests read the impeller's and the fan's delta5 plans, the longest runs of the suite, and
/// share them (a second caller waits for the first's).
fn plan(name: &str, machine: &str) -> Arc<Planned> {
    type Cell = Arc<OnceLock<Arc<Planned>>>;
    static PLANS: OnceLock<Mutex<HashMap<(String, String), Cell>>> = OnceLock::new();
    let cell = PLANS
        .get_or_init(Default::default)
        .lock()
        .expect("the cache's lock")
        .entry((name.to_string(), machine.to_string()))
        .or_default()
        .clone();
    cell.get_or_init(|| Arc::new(plan_once(name, machine)))
        .clone()
}

/// Plans the fixture `name` for `machine`, written even where it collides or fails its
/// self-check (bladed_hub: two blades 3.7 % short, a slicer matter apart from this issue),
/// and reads what was written; the directory is removed.
fn plan_once(name: &str, machine: &str) -> Planned {
    // One directory per call: tests run in parallel and may plan the same part.
    static RUNS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let run = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!(
        "features-collide-{}-{run}-{name}-{machine}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let part =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../fixtures/{name}.step"));
    let out = Command::new(BIN)
        .arg("plan")
        .arg(&part)
        .args([
            "--machine",
            machine,
            "--allow-collisions",
            "--allow-unreachable",
            "--keep-going",
            // The head against the table as the part is modelled: no pedestal under it.
            "--set",
            "pedestal=off",
            "-o",
        ])
        .arg(&dir)
        .output()
        .expect("runs");
    let dir = Out(dir);
    assert!(
        out.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let read = |f: &str| std::fs::read_to_string(dir.0.join(f)).unwrap_or_default();
    let plan: Value = serde_json::from_str(&read("plan.json")).expect("plan.json");
    let points = readback::rows(&read("toolpath.csv"));
    let program = read("program.gcode");
    let collisions = read("collisions.csv");
    drop(dir);
    Planned {
        plan,
        points,
        program,
        collisions,
    }
}

/// Reported colliding moves per feature id.
fn reported(plan: &Value) -> BTreeMap<usize, u64> {
    plan["features"]
        .as_array()
        .expect("features")
        .iter()
        .map(|f| {
            (
                f["id"].as_u64().expect("id") as usize,
                f["collisions"].as_u64().expect("collisions"),
            )
        })
        .collect()
}

/// The highest bead top deposited in each column of a square lattice, with where it is.
struct Columns {
    cell: f64,
    lo: [f64; 2],
    n: usize,
    top: Vec<Option<[f64; 3]>>,
}

impl Columns {
    fn new(cell: f64, lo: [f64; 2], hi: [f64; 2]) -> Columns {
        let n = (((hi[0] - lo[0]).max(hi[1] - lo[1])) / cell).ceil() as usize + 1;
        Columns {
            cell,
            lo,
            n,
            top: vec![None; n * n],
        }
    }

    fn index(&self, x: f64, y: f64) -> Option<usize> {
        let i = ((x - self.lo[0]) / self.cell).floor();
        let j = ((y - self.lo[1]) / self.cell).floor();
        (i >= 0.0 && j >= 0.0 && (i as usize) < self.n && (j as usize) < self.n)
            .then(|| j as usize * self.n + i as usize)
    }

    fn add(&mut self, p: [f64; 3]) {
        if let Some(k) = self.index(p[0], p[1]) {
            if self.top[k].is_none_or(|t| t[2] < p[2]) {
                self.top[k] = Some(p);
            }
        }
    }

    /// The columns' tops within `radius` of `(x, y)` (by column).
    fn near(&self, x: f64, y: f64, radius: f64) -> impl Iterator<Item = [f64; 3]> + '_ {
        let r = (radius / self.cell).ceil() as i64 + 1;
        let (ci, cj) = (
            ((x - self.lo[0]) / self.cell).floor() as i64,
            ((y - self.lo[1]) / self.cell).floor() as i64,
        );
        (-r..=r).flat_map(move |dj| {
            (-r..=r).filter_map(move |di| {
                let (i, j) = (ci + di, cj + dj);
                (i >= 0 && j >= 0 && (i as usize) < self.n && (j as usize) < self.n)
                    .then(|| self.top[j as usize * self.n + i as usize])
                    .flatten()
            })
        })
    }
}

/// The moves (indices of their end points) whose head, at the end point, holds a bead top of
/// the groups (feature, layer) before its own more than [`DEPTH`] inside, for a path whose tool
/// axes are all +Z: above a point the head widens, so the highest bead top of a column is the
/// deepest in it. Columns of 0.25 mm for the nozzle cone and 1 mm for the body.
fn head_hits(points: &[Pt]) -> Vec<usize> {
    let (tip, half, nozzle, body_r, body_top) = HEAD;
    let tan = half.to_radians().tan();
    let cos = half.to_radians().cos();
    let margin = body_r + 2.0;
    let lo = [0, 1].map(|k| points.iter().map(|q| q.p[k]).fold(f64::INFINITY, f64::min) - margin);
    let hi = [0, 1].map(|k| {
        points
            .iter()
            .map(|q| q.p[k])
            .fold(f64::NEG_INFINITY, f64::max)
            + margin
    });
    let mut fine = Columns::new(0.25, lo, hi);
    let mut coarse = Columns::new(1.0, lo, hi);
    let mut hits = vec![];
    let mut group = 0;
    for i in 0..points.len() {
        let q = points[i];
        assert!(q.axis[2] > 1.0 - 1e-6, "tool axis {:?} is not +Z", q.axis);
        if i > 0 && (points[i - 1].feature, points[i - 1].layer) != (q.feature, q.layer) {
            for g in &points[group..i] {
                if g.print {
                    fine.add(g.p);
                    coarse.add(g.p);
                }
            }
            group = i;
        }
        let inside = |m: [f64; 3]| {
            let h = m[2] - q.p[2];
            let r = (m[0] - q.p[0]).hypot(m[1] - q.p[1]);
            let cone = h > DEPTH && h < nozzle - DEPTH && r < tip + h * tan - DEPTH / cos;
            let body = h > nozzle + DEPTH && h < body_top - DEPTH && r < body_r - DEPTH;
            cone || body
        };
        if fine.near(q.p[0], q.p[1], tip + nozzle * tan).any(inside)
            || coarse.near(q.p[0], q.p[1], body_r).any(inside)
        {
            hits.push(i);
        }
    }
    hits
}

/// The hub's sixteen blades, siblings on the hub, planned for the 5-axis printer: no move the
/// independent check finds colliding goes unreported, the blades printed one after the other
/// (the build order as extracted) would have collided, and the hub is printed before them.
#[test]
fn the_bladed_hub_reports_every_colliding_move() {
    let hub = plan("bladed_hub", "delta5");
    let features = hub.plan["features"].as_array().expect("features");
    assert_eq!(features.len(), 17);
    let blades: Vec<usize> = features
        .iter()
        .filter(|f| f["parents"] == serde_json::json!([0]))
        .map(|f| f["id"].as_u64().expect("id") as usize)
        .collect();
    assert_eq!(blades.len(), 16);
    // Dependency order: every hub point before every blade point.
    let first_blade = hub
        .points
        .iter()
        .position(|q| q.feature != 0)
        .expect("blades");
    assert!(hub.points[first_blade..].iter().all(|q| q.feature != 0));

    let reported = reported(&hub.plan);
    let mut found: BTreeMap<usize, u64> = BTreeMap::new();
    for i in head_hits(&hub.points) {
        *found.entry(hub.points[i].feature).or_default() += 1;
    }
    for (f, n) in &found {
        assert!(
            reported.get(f).copied().unwrap_or(0) >= *n,
            "feature {f}: {n} colliding moves found, {:?} reported",
            reported.get(f)
        );
    }

    // The same points, blade after blade: the body meets the blades built before.
    let mut sequential = hub.points.clone();
    sequential.sort_by_key(|q| q.feature);
    let blocked = head_hits(&sequential);
    let blades_hit: std::collections::BTreeSet<usize> =
        blocked.iter().map(|&i| sequential[i].feature).collect();
    assert!(
        blades_hit.len() >= 15,
        "blade after blade, only {blades_hit:?} collide"
    );
}

/// The impeller's and the fan's blades and the capsule's cone boss grow along the normals of
/// curved surfaces, so their tool axes lean far from +Z (the fan's lie flat): the 20 mm body of
/// the head, 8 mm up such an axis, reaches down into the hub or body they stand on, the
/// feature's own higher part, or the table. Those are the collisions reported, and only there:
/// the bases, printed along +Z first, have none, and every colliding move hits material laid
/// before it or the table.
#[test]
fn curved_features_collide_only_where_the_head_leans_over_what_is_built() {
    for (name, machine) in [
        ("impeller", "delta5"),
        ("fan", "delta5"),
        ("capsule", "kuka"),
    ] {
        let run = plan(name, machine);
        for f in run.plan["features"].as_array().expect("features") {
            let id = f["id"].as_u64().expect("id");
            let n = f["collisions"].as_u64().expect("collisions");
            let cleared = f["collisions_cleared_by_tilt"]
                .as_u64()
                .expect("collisions_cleared_by_tilt");
            // The impeller's blades: tilting the axis inside the cone clears the moves whose
            // body meets the hub (a few degrees suffice: the body's rim grazes the hub's top),
            // all but a few gap-fill moves per blade, on the slivers the offset layers cut at
            // the hub's rim: their turn falls outside the search (named in the note). 2 to 13
            // per blade, 41 in all (0 to 1 before the gap fill laid one bead on a sliver's
            // ridge, issue 31 item 4; 3 to 6 before a lifted path kept the points of a gap fill
            // doubling back; 3 to 11, 43 in all, before the B-spline projection's finer grid
            // moved the blades' trims by a hair, issue 34).
            if name == "impeller" && id > 0 {
                assert!(cleared > 0, "{name}: feature {id}: nothing cleared");
                assert!(
                    n <= 14,
                    "{name}: feature {id}: {n} left ({cleared} cleared)"
                );
                let left = left_indices(&run.collisions, id);
                assert_eq!(left.len() as u64, n, "{name}: feature {id}: collisions.csv");
                let other: Vec<usize> = left
                    .into_iter()
                    .filter(|&i| !run.points.get(i).is_some_and(|q| q.gap_fill))
                    .collect();
                assert!(
                    other.is_empty(),
                    "{name}: feature {id}: moves {other:?} left"
                );
            }
            if f["parents"].as_array().expect("parents").is_empty() {
                assert_eq!(n, 0, "{name}: base feature {id} collides");
                assert_eq!(cleared, 0, "{name}: base feature {id} tilted");
                continue;
            }
            if n == 0 {
                assert!(f["first_collision"].is_null());
                continue;
            }
            assert_eq!(f["kind"], "freeform", "{name}: feature {id}");
            let first = &f["first_collision"];
            let hits = &first["hits"];
            assert!(
                hits == "table" || hits.as_u64().is_some_and(|h| h <= id),
                "{name}: feature {id} hits {hits}"
            );
            // The axis at the moves of this feature leans: somewhere more than 30° off +Z.
            let lean = run
                .points
                .iter()
                .filter(|q| q.feature as u64 == id)
                .map(|q| q.axis[2].clamp(-1.0, 1.0).acos().to_degrees())
                .fold(0.0, f64::max);
            assert!(lean > 30.0, "{name}: feature {id} leans only {lean}°");
        }
        tilt_is_continuous(name, &run);
        if name != "impeller" {
            left_moves_meet_the_table_whatever_the_axis(name, machine, &run);
        }
    }
}

/// The path indices of feature `id`'s moves in `collisions.csv` (its `index` and `feature`
/// columns).
fn left_indices(csv: &str, id: u64) -> Vec<usize> {
    csv.lines()
        .skip(1)
        .filter_map(|l| {
            let mut c = l.split(',');
            let index = c.next()?.parse().ok()?;
            (c.next()?.parse::<u64>().ok()? == id).then_some(index)
        })
        .collect()
}

/// The axis within `half` degrees of `planned` nearest +Z: +Z itself, or `planned` turned
/// towards +Z by `half`.
fn highest(planned: [f64; 3], half: f64) -> [f64; 3] {
    let p = planned.map(|x| x / norm(planned));
    let off = p[2].clamp(-1.0, 1.0).acos();
    let h = half.to_radians();
    if off <= h {
        return [0.0, 0.0, 1.0];
    }
    // In the plane of `p` and +Z, `off - h` from +Z.
    let r = p[0].hypot(p[1]);
    let (st, ct) = (off - h).sin_cos();
    [st * p[0] / r, st * p[1] / r, ct]
}

/// One line of `collisions.csv`: the move's end point's row in `toolpath.csv`, what it hits,
/// the planned axes at its start and end (the tolerance cones' axes).
struct Left {
    index: usize,
    hits: String,
    from: [f64; 3],
    planned: [f64; 3],
}

fn left_moves(csv: &str) -> Vec<Left> {
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("index,feature,kind,hits,x,y,z,from_i,from_j,from_k,planned_i,planned_j,planned_k")
    );
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 13, "{l}");
            let num = |k: usize| f[k].parse::<f64>().expect("a number");
            Left {
                index: f[0].parse().expect("an index"),
                hits: f[3].to_string(),
                from: [num(7), num(8), num(9)],
                planned: [num(10), num(11), num(12)],
            }
        })
        .collect()
}

/// The machine's table as this test sees it, in part coordinates: the plane through the
/// lowest bead bottom, within `radius` of the print points' XY bounding-box centre (delta5's
/// disc, which turns with the part) or unbounded (the KUKA cell's table).
struct TableModel {
    z: f64,
    centre: [f64; 2],
    radius: f64,
}

impl TableModel {
    fn new(points: &[Pt], radius: f64) -> TableModel {
        let prints = || points.iter().filter(|q| q.print);
        let z = prints()
            .map(|q| q.p[2] - q.thickness * q.axis[2])
            .fold(f64::INFINITY, f64::min);
        let lo = [0, 1].map(|k| prints().map(|q| q.p[k]).fold(f64::INFINITY, f64::min));
        let hi = [0, 1].map(|k| prints().map(|q| q.p[k]).fold(f64::NEG_INFINITY, f64::max));
        TableModel {
            z,
            centre: [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])],
            radius,
        }
    }

    /// Whether the default head with its tip at `tip` and unit axis `a` reaches more than
    /// 0.1 mm (the planner's tolerance) below the table where the table is: the lowest point
    /// of each of its four rims (nozzle tip, nozzle top, body bottom and top), each a circle
    /// about the axis, lies under the rim's centre, down across the axis.
    fn dips(&self, tip: [f64; 3], a: [f64; 3]) -> bool {
        let (r_tip, half, nozzle, body_r, body_top) = HEAD;
        let down = [a[0] * a[2], a[1] * a[2], a[2] * a[2] - 1.0];
        let n = norm(down);
        let down = if n > 1e-12 {
            down.map(|x| x / n)
        } else {
            [0.0; 3]
        };
        let r_top = r_tip + nozzle * half.to_radians().tan();
        [
            (0.0, r_tip),
            (nozzle, r_top),
            (nozzle, body_r),
            (body_top, body_r),
        ]
        .iter()
        .any(|&(h, r)| {
            let p: [f64; 3] = std::array::from_fn(|k| tip[k] + h * a[k] + r * down[k]);
            p[2] < self.z - 0.1
                && (p[0] - self.centre[0]).hypot(p[1] - self.centre[1]) <= self.radius
        })
    }

    /// Whether the head dips into the table anywhere along the move from (`a`, axis `aa`) to
    /// (`b`, axis `ab`), the tip and the axis interpolated linearly (the axis normalised), in
    /// 200 steps, the start left out (the move before ends there).
    fn sweep_dips(&self, a: [f64; 3], aa: [f64; 3], b: [f64; 3], ab: [f64; 3]) -> bool {
        (1..=200).any(|k| {
            let t = k as f64 / 200.0;
            let tip: [f64; 3] = std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t);
            let ax: [f64; 3] = std::array::from_fn(|i| aa[i] * (1.0 - t) + ab[i] * t);
            let n = norm(ax);
            n > 1e-9 && self.dips(tip, ax.map(|x| x / n))
        })
    }

    /// Whether the head at `tip` dips into the table for every axis within `half` degrees of
    /// `planned` and within `b_limit` degrees of +Z: tried on the cone's axis nearest +Z and on
    /// rings 1° apart, 72 directions each.
    fn no_axis_clears(&self, tip: [f64; 3], planned: [f64; 3], half: f64, b_limit: f64) -> bool {
        let p = planned.map(|x| x / norm(planned));
        let e1 = {
            let up = [-p[0] * p[2], -p[1] * p[2], 1.0 - p[2] * p[2]];
            let n = norm(up);
            if n > 1e-9 {
                up.map(|x| x / n)
            } else {
                let x = [1.0 - p[0] * p[0], -p[0] * p[1], -p[0] * p[2]];
                x.map(|v| v / norm(x))
            }
        };
        let e2 = cross(p, e1);
        let axis = |t: f64, phi: f64| -> [f64; 3] {
            let (st, ct) = t.to_radians().sin_cos();
            let (sp, cp) = phi.to_radians().sin_cos();
            std::array::from_fn(|k| ct * p[k] + st * (cp * e1[k] + sp * e2[k]))
        };
        let within = |a: [f64; 3]| a[2].clamp(-1.0, 1.0).acos().to_degrees() <= b_limit + 1e-9;
        // The highest axis of the cone first: towards +Z by the half-angle (or +Z itself).
        let off = p[2].clamp(-1.0, 1.0).acos().to_degrees();
        let highest = if off <= half {
            [0.0, 0.0, 1.0]
        } else {
            axis(half, 0.0)
        };
        if !self.dips(tip, highest) {
            return false;
        }
        (0..=half.ceil() as usize).all(|t| {
            (0..72).all(|j| {
                let a = axis((t as f64).min(half), 5.0 * j as f64);
                !within(a) || self.dips(tip, a)
            })
        })
    }
}

/// Every colliding move left (`collisions.csv`, as many as `plan.json` counts) hits the table,
/// and is one of: (a) a move with an end where the head meets the table whatever axis it takes
/// inside the tolerance cone about that point's planned axis (and delta5's B limit), checked
/// here on a fine set of axes apart from the planner's search; (a') a move the head meets the
/// table on even with both ends at their cone's highest axis; (b) a move clearable alone, which
/// must then be one whose clearing breaks the axis's step bound, or leaves a neighbouring move
/// on the table, or that ends its bead. The counts per feature go to stderr.
fn left_moves_meet_the_table_whatever_the_axis(name: &str, machine: &str, run: &Planned) {
    let (_, half) = SMOOTHING;
    let m = MachineProfile::builtin(if machine == "kuka" {
        MachineKind::Kuka
    } else {
        MachineKind::Delta5
    });
    let (radius, b_limit) = match &m.delta5 {
        Some(g) => (
            g.table_radius,
            g.b_limits_deg[0].abs().max(g.b_limits_deg[1].abs()),
        ),
        None => (f64::INFINITY, 180.0),
    };
    let table = TableModel::new(&run.points, radius);
    let left = left_moves(&run.collisions);
    let total: u64 = reported(&run.plan).values().sum();
    assert_eq!(
        left.len() as u64,
        total,
        "{name}: collisions.csv against plan.json"
    );
    // Per feature: moves with an end where the head meets the table whatever the axis inside
    // the cone; moves the head meets the table on with both ends at their cone's highest axis
    // (the axis the head's lowest point is highest on); and the others, clearable alone.
    let mut counts: BTreeMap<usize, [usize; 3]> = BTreeMap::new();
    let mut alone = vec![];
    let pts = &run.points;
    // All on the table, but for one move of the fan's since the gap fill lays one bead on
    // the ridge of a blade's thin edge (issue 31, item 4): blade 5's first layer, its body on
    // blade 1 (named in the note).
    let elsewhere: Vec<usize> = left
        .iter()
        .filter(|l| l.hits != "table")
        .map(|l| l.index)
        .collect();
    assert!(
        elsewhere.len() <= 1,
        "{name}: moves {elsewhere:?} hit the part, not the table"
    );
    for l in left.iter().filter(|l| l.hits == "table") {
        let i = l.index;
        let e = counts.entry(pts[i].feature).or_default();
        let from = i.saturating_sub(1);
        if table.no_axis_clears(pts[i].p, l.planned, half, b_limit)
            || table.no_axis_clears(pts[from].p, l.from, half, b_limit)
        {
            e[0] += 1;
            continue;
        }
        let (a0, a1) = (highest(l.from, half), highest(l.planned, half));
        if table.sweep_dips(pts[from].p, a0, pts[i].p, a1) {
            e[1] += 1;
        } else {
            e[2] += 1;
            alone.push((i, a0, a1));
        }
    }
    eprintln!("{name}: per feature (an end no axis clears, highest axes dip between, clearable alone): {counts:?}");
    // The clearable ones, cleared alone: both ends turned to their cone's highest axis, all
    // else as written. The turn then breaks the bound on the axis's step to a neighbouring
    // point of its bead, or a neighbouring move meets the table (the tilt, which turns whole
    // stretches, would have to clear that one too), or the move ends its bead.
    let steps = step_bounds(run);
    let mut missed = vec![];
    for &(i, a0, a1) in &alone {
        let steep = (i >= 2 && !steps.holds(&pts[i - 2], pts[i - 2].axis, &pts[i - 1], a0))
            || !steps.holds(&pts[i - 1], a0, &pts[i], a1)
            || (i + 1 < pts.len() && !steps.holds(&pts[i], a1, &pts[i + 1], pts[i + 1].axis));
        let before = i >= 2 && table.sweep_dips(pts[i - 2].p, pts[i - 2].axis, pts[i - 1].p, a0);
        let after =
            i + 1 < pts.len() && table.sweep_dips(pts[i].p, a1, pts[i + 1].p, pts[i + 1].axis);
        // The last point of its bead, the next move a travel to the next layer: there the
        // tilt's key search leaves it (a limit of the search, not of the cone).
        let ends_bead = pts.get(i + 1).is_some_and(|n| !n.print);
        if !(steep || before || after || ends_bead) {
            missed.push(i);
        }
    }
    // None, until the gap fill laid one bead on the ridge of the blades' thin edges (issue 31,
    // item 4): since, a few the tilt's search does not clear though each could be alone (16 of
    // the fan's 49,982 on 64b4102; named in the note): at most one in a thousand.
    assert!(
        missed.len() * 1000 <= left.len(),
        "{name}: moves {missed:?} could be cleared alone, within the step bound and their neighbours clear"
    );
}

/// The most the axis may turn from one print point to the next of its bead after the head's
/// avoidance: the feature's largest step after smoothing (`plan.json`) plus the tilt blend's
/// slope (two cone half-angles per window) times the step's length.
struct StepBounds {
    smoothed: BTreeMap<usize, f64>,
    slope: f64,
}

impl StepBounds {
    /// Whether the axis `aa` at `a` and `ab` at `b` keep the bound (always, where `b` does not
    /// continue `a`'s bead).
    fn holds(&self, a: &Pt, aa: [f64; 3], b: &Pt, ab: [f64; 3]) -> bool {
        if !(b.print && a.feature == b.feature && a.layer == b.layer) {
            return true;
        }
        let step = norm(cross(aa, ab)).atan2(dot(aa, ab)).to_degrees();
        let len = norm(sub(b.p, a.p));
        step <= self.smoothed[&b.feature] + self.slope * len + 1e-3
    }
}

fn step_bounds(run: &Planned) -> StepBounds {
    let (window, half) = SMOOTHING;
    let smoothed = run.plan["features"]
        .as_array()
        .expect("features")
        .iter()
        .map(|f| {
            let step = f["orientation_step_max_deg_after"].as_f64().unwrap_or(0.0);
            (f["id"].as_u64().expect("id") as usize, step)
        })
        .collect();
    StepBounds {
        smoothed,
        slope: 2.0 * half / window,
    }
}

/// The default orientation smoothing: window (mm) and the cone's half-angle (degrees).
const SMOOTHING: (f64, f64) = (5.0, 30.0);

/// The axes along every bead after the head's avoidance turn, from one print point to the
/// next, by at most the feature's largest step after smoothing (`plan.json`) plus the tilt
/// blend's slope (two cone half-angles per window, the most a turn inside the cone can change
/// over one) times the step's length: the tilt keeps the smoothed axes continuous.
fn tilt_is_continuous(name: &str, run: &Planned) {
    let steps = step_bounds(run);
    for w in run.points.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        assert!(
            steps.holds(a, a.axis, b, b.axis),
            "{name}: feature {} turns {:?} -> {:?} over {} mm, past its bound",
            b.feature,
            a.axis,
            b.axis,
            norm(sub(b.p, a.p))
        );
        assert!((norm(b.axis) - 1.0).abs() < 1e-4, "{name}: axis not unit");
    }
}

/// A bead: its top centreline from `a` to `b`, the tool axis, thickness and width.
/// A bead: from, to, axis, thickness, width, and its (feature, layer).
type Bead = ([f64; 3], [f64; 3], [f64; 3], f64, f64, (usize, usize));

/// Beads laid so far, indexed by 1 mm cells.
#[derive(Default)]
struct Beads {
    all: Vec<Bead>,
    cells: HashMap<[i64; 3], Vec<usize>>,
}

impl Beads {
    fn add(&mut self, a: [f64; 3], q: &Pt) {
        let k = self.all.len();
        self.all
            .push((a, q.p, q.axis, q.thickness, q.width, (q.feature, q.layer)));
        let r = q.width.max(q.thickness);
        let lo: [i64; 3] = std::array::from_fn(|i| (a[i].min(q.p[i]) - r).floor() as i64);
        let hi: [i64; 3] = std::array::from_fn(|i| (a[i].max(q.p[i]) + r).floor() as i64);
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    self.cells.entry([x, y, z]).or_default().push(k);
                }
            }
        }
    }

    /// Whether `t` lies inside a bead: under its top by more than 0.02 mm and less than its
    /// thickness, and nearer its centreline across than half its width, by 0.02 mm.
    /// Whether `t` lies inside a bead, but for those of the layers `own` (feature, layer): a
    /// travel's first step up off the layer it leaves, and its last step down onto the layer
    /// it goes to, meet that layer's beads beside it at its own height, within a bead's tilt
    /// where the layer curves and the smoothed axis leans, or a step of a transition band
    /// over offset layers.
    fn inside(&self, t: [f64; 3], own: [Option<(usize, usize)>; 2]) -> bool {
        let key = t.map(|v| v.floor() as i64);
        let Some(list) = self.cells.get(&key) else {
            return false;
        };
        list.iter().any(|&k| {
            let (a, b, axis, th, w, layer) = self.all[k];
            if own.contains(&Some(layer)) {
                return false;
            }
            let ab = sub(b, a);
            let len2 = dot(ab, ab);
            let s = if len2 > 0.0 {
                (dot(sub(t, a), ab) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let c = [a[0] + ab[0] * s, a[1] + ab[1] * s, a[2] + ab[2] * s];
            let d = sub(t, c);
            let along = dot(d, axis);
            let across = sub(d, [axis[0] * along, axis[1] * along, axis[2] * along]);
            along < -0.02 && along > -th + 0.02 && dot(across, across).sqrt() < w / 2.0 - 0.02
        })
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Every travel (`G0`) of the program, followed in steps of at most 0.1 mm of the tip in part
/// coordinates, against the beads laid before it; for delta5 also the bed's turn in all
/// (degrees of B and C) below the safe height of each travel, at most `reorient_lift_deg`.
fn check_travels(name: &str, machine: MachineKind, run: &Planned) {
    let m = MachineProfile::builtin(machine);
    let g = m.delta5.clone();
    let off = readback::offset(&run.program);
    let to_part = |j: [f64; 5]| match &g {
        Some(g) => robot_post::delta5::forward(j, g, off).0,
        None => [j[0] - off[0], j[1] - off[1], j[2] - off[2]],
    };
    let safe = run
        .program
        .lines()
        .find_map(|l| l.strip_prefix("; safe height Z"))
        .and_then(|l| l.split_whitespace().next())
        .map(|z| z.parse::<f64>().expect("safe height"));
    let prints: Vec<(usize, Pt)> = run
        .points
        .iter()
        .enumerate()
        .filter(|(_, q)| q.print)
        .map(|(i, q)| (i, *q))
        .collect();
    let mut beads = Beads::default();
    let mut next: usize = 0;
    let mut turn = 0.0;
    let mut from = [0.0; 5];
    let (mut travels, mut checked) = (0, 0);
    for (rapid, to, e) in readback::moves(&run.program) {
        if rapid {
            let (a, b) = (to_part(from), to_part(to));
            let joint = ((to[3] - from[3]).abs() + (to[4] - from[4]).abs()) / 0.05;
            let n = ((dot(sub(b, a), sub(b, a)).sqrt() / 0.1).max(joint).ceil() as usize).max(1);
            for k in 1..=n {
                let f = k as f64 / n as f64;
                let j: [f64; 5] = std::array::from_fn(|i| from[i] + (to[i] - from[i]) * f);
                let t = to_part(j);
                assert!(
                    !beads.inside(
                        t,
                        [
                            next.checked_sub(1)
                                .map(|k| (prints[k].1.feature, prints[k].1.layer)),
                            prints.get(next).map(|(_, q)| (q.feature, q.layer))
                        ]
                    ),
                    "{name}: a travel to {to:?} passes through a bead at {t:?}"
                );
                checked += 1;
            }
            if let Some(safe) = safe {
                if from[2].min(to[2]) < safe - 1e-3 {
                    turn += (to[3] - from[3]).abs() + (to[4] - from[4]).abs();
                }
            }
        } else if !e.is_some_and(|e| e < 0.0) {
            if turn > 0.0 {
                travels += 1;
            }
            let lift = g.as_ref().map_or(f64::INFINITY, |g| g.reorient_lift_deg);
            assert!(
                turn <= lift + 1e-6,
                "{name}: a travel turns the bed {turn}° below the safe height"
            );
            turn = 0.0;
            // Beads laid: the planned print points this move reaches.
            let p = to_part(to);
            while next < prints.len() {
                let (i, q) = prints[next];
                if dot(sub(q.p, p), sub(q.p, p)).sqrt() > 0.01 {
                    break;
                }
                if i > 0 {
                    beads.add(run.points[i - 1].p, &q);
                }
                next += 1;
            }
        }
        from = to;
    }
    assert_eq!(next, prints.len(), "{name}: every print point reached");
    assert!(checked > 0, "{name}: no travel checked");
    if g.is_some() {
        assert!(travels > 0, "{name}: no travel turns the bed");
    }
}

/// Marlin: two boxes side by side, a plate with two bosses; delta5: the impeller, the fan and
/// the sphere boss.
#[test]
fn no_travel_passes_through_beads_or_turns_the_bed_below_the_safe_height() {
    for (name, machine) in [
        ("two_solids", MachineKind::Marlin),
        ("plate_boss_boss", MachineKind::Marlin),
        ("sphere_boss", MachineKind::Delta5),
        ("impeller", MachineKind::Delta5),
        ("fan", MachineKind::Delta5),
    ] {
        let run = plan(name, machine.as_str());
        check_travels(name, machine, &run);
    }
}
