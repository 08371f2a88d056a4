  /* The simulation view (issue 36 item 2): function declarations only (hoisted), called by the
     viewer at its steps: simStart (data, bounds), simSetup (WebGL buffers, panel), simPart (the
     part's frame in the view), simDrawMachine, simDrawHead and simDrawDots (in draw), simSplit
     (the path's drawn share). The machine is orange (1, 0.36, 0), a colour nothing else has.

     Arm (data.simulation.machine.kind "arm"): OPW forward kinematics (Brandstötter, Angerer &
     Hofbaur 2014, as robot_post::kuka::ArmModel::forward), θi = (Ai·sign_i − offset_i) in
     radians, in the robot's base frame:
       shoulder S = R_z(θ1)·(a1, b, c1),
       elbow    E = S + R_z(θ1)·c2·(sin θ2, 0, cos θ2),
       with φ = θ2 + θ3: elbow offset E' = E + R_z(θ1)·a2·(cos φ, 0, −sin φ),
       wrist centre W = E' + R_z(θ1)·c3·(sin φ, 0, cos φ)
         (so W = R_z(θ1)·(cx1, b, cz1), cx1 = c2 sin θ2 + k sin(φ + ψ3) + a1,
          cz1 = c2 cos θ2 + k cos(φ + ψ3) + c1, k = hypot(a2, c3), ψ3 = atan2(a2, c3)),
       R = R_z(θ1)·R_y(φ)·R_z(θ4)·R_y(θ5)·R_z(θ6), flange F = W + c4·R·ẑ,
       tool tip = F + R·t_tool, tool orientation R·R_tool ($TOOL), the head along its −Z;
     then into the tool path's frame by robot_to_part ((($BASE)·offset)⁻¹, from the page's data).
     Table (kind "table"): a tool-path point p is drawn at K + R_y(−B)·R_z(−C)·(p − K), K the
     crossing of the B and C axes (table_above_b_axis under the table's centre); the head stays
     vertical over the move's point. */
  /* The simulation's state, set by simStart (declared only: this script runs after the
     viewer's, its declarations hoisted, so an initialiser here would run last). */
  var S;

  /* Column-major 4 × 4 products and rigid transforms. */
  function simMul4(a, b) {
    var m = new Float32Array(16);
    for (var c = 0; c < 4; c++) for (var r = 0; r < 4; r++) {
      var s = 0; for (var k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k]; m[c * 4 + r] = s;
    }
    return m;
  }
  function simApply(m, p) {
    return [m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12],
      m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13],
      m[2] * p[0] + m[6] * p[1] + m[10] * p[2] + m[14]];
  }
  function simTurn(m, v) {
    return [m[0] * v[0] + m[4] * v[1] + m[8] * v[2], m[1] * v[0] + m[5] * v[1] + m[9] * v[2],
      m[2] * v[0] + m[6] * v[1] + m[10] * v[2]];
  }
  /* 3 × 3 rotations, rows. */
  function simRz(t) { var c = Math.cos(t), s = Math.sin(t); return [[c, -s, 0], [s, c, 0], [0, 0, 1]]; }
  function simRy(t) { var c = Math.cos(t), s = Math.sin(t); return [[c, 0, s], [0, 1, 0], [-s, 0, c]]; }
  function simMul3(a, b) {
    var m = [[0, 0, 0], [0, 0, 0], [0, 0, 0]];
    for (var i = 0; i < 3; i++) for (var j = 0; j < 3; j++) for (var k = 0; k < 3; k++) m[i][j] += a[i][k] * b[k][j];
    return m;
  }
  function simCol(r, j) { return [r[0][j], r[1][j], r[2][j]]; }
  function simAdd(a, b, s) { return [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]; }

  /* The arm at joints j (degrees): its chain's points and the tool's frame, in the tool path's
     frame (see the formulas above). */
  function simArm(j) {
    var m = S.m, o = m.opw, a1 = o[0], a2 = o[1], b = o[2], c1 = o[3], c2 = o[4], c3 = o[5], c4 = o[6];
    var q = [0, 1, 2, 3, 4, 5].map(function (i) { return (j[i] * m.signs[i] - m.offsets[i]) * Math.PI / 180; });
    var R1 = simRz(q[0]);
    function arm(x, y, z) { return [R1[0][0] * x + R1[0][1] * y, R1[1][0] * x + R1[1][1] * y, z]; }
    var phi = q[1] + q[2];
    var S0 = arm(a1, 0, c1), Sh = arm(a1, b, c1);
    var E = simAdd(Sh, arm(Math.sin(q[1]), 0, Math.cos(q[1])), c2);
    var E2 = simAdd(E, arm(Math.cos(phi), 0, -Math.sin(phi)), a2);
    var W = simAdd(E2, arm(Math.sin(phi), 0, Math.cos(phi)), c3);
    var R = simMul3(simMul3(simMul3(R1, simRy(phi)), simMul3(simRz(q[3]), simRy(q[4]))), simRz(q[5]));
    var F = simAdd(W, simCol(R, 2), c4);
    var T = m.tool, tr = [[T[0], T[4], T[8]], [T[1], T[5], T[9]], [T[2], T[6], T[10]]];
    var tip = F;
    for (var k = 0; k < 3; k++) tip = simAdd(tip, simCol(R, k), T[12 + k]);
    var Rt = simMul3(R, tr), G = m.robot_to_part;
    function at(p) { return simApply(G, p); }
    return {
      base: at([0, 0, 0]), column: at([0, 0, c1]), shoulder0: at(S0), shoulder: at(Sh), elbow: at(E),
      elbow2: at(E2), wrist: at(W), flange: at(F), tip: at(tip),
      a2axis: simTurn(G, arm(0, 1, 0)), up: simTurn(G, [0, 0, 1]),
      x: simTurn(G, simCol(Rt, 0)), y: simTurn(G, simCol(Rt, 1)), z: simTurn(G, simCol(Rt, 2))
    };
  }

  /* The table's turn at B, C (degrees): the column-major transform of the tool path's frame into
     the view, K + R_y(−B)·R_z(−C)·(p − K). */
  function simTableModel(bDeg, cDeg) {
    var R = simMul3(simRy(-bDeg * Math.PI / 180), simRz(-cDeg * Math.PI / 180));
    var K = S.K, m = new Float32Array(16);
    for (var i = 0; i < 3; i++) {
      for (var j = 0; j < 3; j++) m[j * 4 + i] = R[i][j];
      m[12 + i] = K[i] - (R[i][0] * K[0] + R[i][1] * K[1] + R[i][2] * K[2]);
    }
    m[15] = 1;
    return m;
  }

  function simJoints(i) {
    var d = S.dof, j = [];
    for (var k = 0; k < d; k++) j.push(S.joints[i * d + k]);
    return j;
  }

  /* Reads the data and grows the view's bounds by the machine (the arm's chain at some moves and
     its base, or the sphere the table sweeps). */
  function simStart() {
    var d = data.simulation;
    if (!d || d.moves === 0) return;
    S = { d: d, m: d.machine, n: d.moves, dof: d.names.length, number: u32(d.number), point: u32(d.point),
      xyz: f32(d.xyz), joints: f32(d.joints), flags: u32(d.flags), drawnAt: u32(d.drawn_at), cur: 0,
      model: null, on: true, orange: [1.0, 0.36, 0.0],
      /* Dots of collisions, near-singular wrists and joints near a limit. */
      flagColours: [[1, 0, 0, 1], [0.55, 0.1, 0.95, 1], [0.85, 0, 0.75, 1]] };
    /* The part's size, before the machine's: the tool-axis ticks keep their length. */
    S.partSize = lo3[0] <= hi3[0] ? Math.max(hi3[0] - lo3[0], hi3[1] - lo3[1], hi3[2] - lo3[2], 1e-3) : 1;
    if (S.m.kind === "table") {
      var t = S.m;
      S.thick = Math.max(0.04 * t.radius, 1);
      S.K = [t.centre[0], t.centre[1], t.z - t.above];
      var rho = Math.hypot(t.radius, Math.abs(t.above) + S.thick);
      grow(S.K[0] - rho, S.K[1] - rho, S.K[2] - rho); grow(S.K[0] + rho, S.K[1] + rho, S.K[2] + rho);
    } else {
      var step = Math.max(1, Math.floor(S.n / 50));
      for (var i = 0; i < S.n; i += step) {
        var a = simArm(simJoints(i));
        ["base", "shoulder", "elbow", "wrist", "flange"].forEach(function (k) { grow(a[k][0], a[k][1], a[k][2]); });
      }
    }
  }

  /* Triangles (positions and normals) of solids, appended to arrays. */
  function simCylinder(out, p, q, r) {
    var ax = sub(q, p), len = Math.hypot(ax[0], ax[1], ax[2]);
    if (!(len > 1e-6) || !(r > 0)) return;
    var a = norm(ax), h = Math.abs(a[2]) < 0.9 ? [0, 0, 1] : [1, 0, 0];
    var u = norm(cross(a, h)), v = cross(a, u), N = 16;
    function ring(k) { var t = 2 * Math.PI * k / N; return [Math.cos(t), Math.sin(t)]; }
    function pt(c, cs, s) { return [c[0] + s * (cs[0] * u[0] + cs[1] * v[0]), c[1] + s * (cs[0] * u[1] + cs[1] * v[1]), c[2] + s * (cs[0] * u[2] + cs[1] * v[2])]; }
    function tri(A, B, C, n) { out.pos.push.apply(out.pos, A.concat(B, C)); out.nrm.push.apply(out.nrm, n.concat(n, n)); }
    for (var k = 0; k < N; k++) {
      var c0 = ring(k), c1 = ring(k + 1), cm = ring(k + 0.5);
      var n = [cm[0] * u[0] + cm[1] * v[0], cm[0] * u[1] + cm[1] * v[1], cm[0] * u[2] + cm[1] * v[2]];
      var A = pt(p, c0, r), B = pt(p, c1, r), C = pt(q, c1, r), D = pt(q, c0, r);
      tri(A, B, C, n); tri(A, C, D, n);
      tri(p, B, A, [-a[0], -a[1], -a[2]]); tri(q, D, C, a);
    }
  }

  /* The arm's links at the current move, as cylinders in the tool path's frame. */
  function simArmSolids(a) {
    var o = S.m.opw, r = 0.07 * Math.max(Math.abs(o[4]), Math.abs(o[5]), 100), out = { pos: [], nrm: [] };
    var foot = simAdd(a.base, a.up, 0.15 * o[3]);
    simCylinder(out, a.base, foot, 2.4 * r);
    simCylinder(out, foot, a.column, 1.5 * r);
    simCylinder(out, a.column, a.shoulder0, 1.3 * r);
    simCylinder(out, a.shoulder0, a.shoulder, 1.2 * r);
    simCylinder(out, simAdd(a.shoulder, a.a2axis, -1.3 * r), simAdd(a.shoulder, a.a2axis, 1.3 * r), 1.3 * r);
    simCylinder(out, a.shoulder, a.elbow, r);
    simCylinder(out, simAdd(a.elbow, a.a2axis, -1.1 * r), simAdd(a.elbow, a.a2axis, 1.1 * r), 1.05 * r);
    simCylinder(out, a.elbow, a.elbow2, 0.9 * r);
    simCylinder(out, a.elbow2, a.wrist, 0.8 * r);
    simCylinder(out, a.wrist, a.flange, 0.55 * r);
    var top = simAdd(a.tip, a.z, -S.d.head_length);
    simCylinder(out, a.flange, top, 0.3 * r);
    return out;
  }

  /* The table's disc and its C spindle (in the tool path's frame, turned by the model), and the
     B axis's shaft (in the view: it does not turn). */
  function simTableSolids() {
    var t = S.m, c = [t.centre[0], t.centre[1], t.z], out = { pos: [], nrm: [] }, shaft = { pos: [], nrm: [] };
    var under = [c[0], c[1], c[2] - S.thick];
    simCylinder(out, under, c, t.radius);
    if (t.above > S.thick) simCylinder(out, S.K, under, 0.12 * t.radius);
    var half = 1.15 * t.radius;
    simCylinder(shaft, [S.K[0], S.K[1] - half, S.K[2]], [S.K[0], S.K[1] + half, S.K[2]], 0.05 * t.radius);
    return { turned: out, fixed: shaft };
  }

  /* Spokes and rim drawn on the table's top, so that its turn shows. */
  function simTableLines() {
    var t = S.m, l = [], z = t.z + 0.002 * t.radius, N = 48;
    for (var k = 0; k < N; k++) {
      var a = 2 * Math.PI * k / N, b = 2 * Math.PI * (k + 1) / N;
      l.push(t.centre[0] + t.radius * Math.cos(a), t.centre[1] + t.radius * Math.sin(a), z,
        t.centre[0] + t.radius * Math.cos(b), t.centre[1] + t.radius * Math.sin(b), z);
    }
    for (var s = 0; s < 6; s++) {
      var w = Math.PI * s / 3;
      l.push(t.centre[0], t.centre[1], z, t.centre[0] + t.radius * Math.cos(w), t.centre[1] + t.radius * Math.sin(w), z);
    }
    return new Float32Array(l);
  }

  function simUpload(buf, arr) { gl.bindBuffer(gl.ARRAY_BUFFER, buf); gl.bufferData(gl.ARRAY_BUFFER, arr, gl.DYNAMIC_DRAW); }
  function simMesh(solid) {
    var m = { pos: gl.createBuffer(), nrm: gl.createBuffer(), n: solid.pos.length / 3 };
    simUpload(m.pos, new Float32Array(solid.pos)); simUpload(m.nrm, new Float32Array(solid.nrm));
    return m;
  }

  /* Dots at the moves numbered in `list` (indices into the embedded moves), as markGeometry's. */
  function simDots(list) {
    var v = [];
    list.forEach(function (i) {
      var p = [S.xyz[3 * i], S.xyz[3 * i + 1], S.xyz[3 * i + 2]];
      if (!p.every(isFinite)) return;
      DOT.forEach(function (c) { v.push(p[0], p[1], p[2], p[0], p[1], p[2], c[0], c[1], 1); });
    });
    return { buf: buffer(new Float32Array(v)), n: v.length / 9 };
  }

  function simFlagText(i) {
    var f = S.flags[i], parts = [], names = S.d.names, j = simJoints(i), m = S.m;
    if (f & 1) parts.push("the head collides");
    for (var k = 0; k < S.dof; k++) {
      if (f & (4 << k)) {
        parts.push(names[k] + " " + j[k].toFixed(1) + "\u00b0 within " + S.d.margins.limit_deg + "\u00b0 of its limits " +
          m.min[k] + "\u2026" + m.max[k]);
      }
    }
    if (f & 2) parts.push("wrist near its singularity (A5 " + j[4].toFixed(1) + "\u00b0)");
    return parts.join("; ");
  }

  /* WebGL buffers, the panel, its list and the scrubber. */
  function simSetup() {
    if (!S) return;
    S.head = overlay(S.d.head);
    document.getElementById("sim").style.display = "block";
    var range = document.getElementById("simMove");
    range.max = String(S.n - 1);
    if (S.m.kind === "table") {
      var solids = simTableSolids();
      S.turned = simMesh(solids.turned); S.fixed = simMesh(solids.fixed);
      var l = simTableLines();
      S.spokes = { tri: buffer(new Float32Array(0)), nt: 0, lines: buffer(l), nl: l.length / 3 };
    } else {
      S.links = simMesh({ pos: [], nrm: [] });
    }
    var byKind = [[], [], []], listed = [];
    for (var i = 0; i < S.n; i++) {
      var f = S.flags[i];
      if (f === 0) continue;
      listed.push(i);
      byKind[(f & 1) ? 0 : (f & 2) ? 1 : 2].push(i);
    }
    S.dots = byKind.map(simDots);
    simList(listed);
    range.addEventListener("input", function () { simStop(); simShow(+range.value); });
    document.getElementById("simPlay").addEventListener("click", function () {
      if (S.playing) { simStop(); return; }
      if (S.cur >= S.n - 1) simShow(0);
      S.playing = true; document.getElementById("simPlay").textContent = "pause";
      window.requestAnimationFrame(simStep);
    });
    document.getElementById("showSim").addEventListener("change", function () {
      S.on = document.getElementById("showSim").checked; draw();
    });
    var want = /(?:^#|&)sim=([0-9.]+)/.exec(location.hash);
    var at = want ? Math.round(Math.max(0, Math.min(1, +want[1])) * (S.n - 1)) : 0;
    simShow(isFinite(at) ? at : 0, true);
  }

  /* Play: through the moves in about 20 s, a frame at a time. */
  function simStep() {
    if (!S.playing) return;
    var next = Math.min(S.n - 1, S.cur + Math.max(1, Math.round(S.n / 1200)));
    simShow(next);
    if (next >= S.n - 1) simStop(); else window.requestAnimationFrame(simStep);
  }
  function simStop() {
    S.playing = false;
    document.getElementById("simPlay").textContent = "play";
  }

  /* The "Machine" list: one line a flagged move; a click goes to it. */
  function simList(listed) {
    var fl = S.d.flagged, el = document.getElementById("simflagged");
    if (fl.any === 0) { el.style.display = "none"; return; }
    document.getElementById("simflaggedhead").textContent = "Machine (" + fl.any.toLocaleString() + " moves)";
    document.getElementById("simflaggedsum").textContent = [
      [fl.collision, "in collision (red)"], [fl.near_singularity, "near the wrist singularity (violet)"],
      [fl.near_limit, "near a joint limit (magenta)"]
    ].filter(function (e) { return e[0] > 0; }).map(function (e) { return e[0].toLocaleString() + " " + e[1]; }).join(", ") +
      "; click one to go to it";
    var box = document.getElementById("simflaggedlist"), frag = document.createDocumentFragment();
    listed.forEach(function (i) {
      var row = document.createElement("div"); row.setAttribute("data-sim", String(i));
      var k = document.createElement("span"), f = S.flags[i];
      k.className = "kind " + ((f & 1) ? "collision" : (f & 2) ? "singular" : "limit");
      k.textContent = "move " + S.number[i].toLocaleString();
      row.appendChild(k); row.appendChild(document.createTextNode(simFlagText(i)));
      frag.appendChild(row);
    });
    box.appendChild(frag);
    box.addEventListener("click", function (ev) {
      var row = ev.target.closest ? ev.target.closest("div[data-sim]") : null;
      if (row) simShow(+row.getAttribute("data-sim"));
    });
    if (fl.any > listed.length) {
      document.getElementById("simflaggedleft").textContent = "and " + (fl.any - listed.length).toLocaleString() +
        " more flagged moves, neither listed nor drawn";
    }
    document.body.setAttribute("data-sim-flagged", String(listed.length));
  }

  /* Goes to embedded move i: the machine's pose, the panel, the page's attributes. */
  function simShow(i, quiet) {
    S.cur = i;
    document.getElementById("simMove").value = String(i);
    var j = simJoints(i), tip, axis, x;
    if (S.m.kind === "table") {
      S.model = simTableModel(j[0], j[1]);
      tip = [S.xyz[3 * i], S.xyz[3 * i + 1], S.xyz[3 * i + 2]];
      axis = simTurn(simTableModel(0, -j[1]), simTurn(simTableModel(-j[0], 0), [0, 0, 1]));
      S.headAt = simHeadMatrix(simApply(S.model, tip), [1, 0, 0], [0, 1, 0], [0, 0, 1]);
    } else {
      var a = simArm(j);
      var solids = simArmSolids(a);
      simUpload(S.links.pos, new Float32Array(solids.pos)); simUpload(S.links.nrm, new Float32Array(solids.nrm));
      S.links.n = solids.pos.length / 3;
      tip = a.tip; axis = [-a.z[0], -a.z[1], -a.z[2]]; x = a.x;
      S.headAt = simHeadMatrix(tip, x, [-a.y[0], -a.y[1], -a.y[2]], axis);
    }
    if (S.dot) gl.deleteBuffer(S.dot.buf);
    S.dot = simDots([i]);
    var names = S.d.names, f = S.flags[i], tb = document.getElementById("simjoints");
    tb.textContent = "";
    names.forEach(function (nm, k) {
      var tr = document.createElement("tr");
      if (f & (4 << k)) tr.className = "near";
      [nm, j[k].toFixed(2) + "\u00b0", S.m.min[k] === null ? "unlimited" : S.m.min[k] + "\u2026" + S.m.max[k]].forEach(function (s, c) {
        var td = document.createElement("td"); td.textContent = s; if (c > 0) td.className = "v"; tr.appendChild(td);
      });
      tb.appendChild(tr);
    });
    document.getElementById("simtext").textContent = "move " + S.number[i].toLocaleString() + " of " +
      S.d.total.toLocaleString() + " (tool path point " + S.point[i].toLocaleString() + ")" +
      (S.n < S.d.total ? "; " + S.n.toLocaleString() + " of them embedded" : "") + simOff(i, tip);
    document.getElementById("simflags").textContent = f ? simFlagText(i) : "";
    function fmt(v) { return v.map(function (x) { return x.toFixed(4); }).join(","); }
    document.body.setAttribute("data-sim-move", String(S.number[i]));
    document.body.setAttribute("data-sim-tip", fmt(tip));
    document.body.setAttribute("data-sim-axis", fmt(axis));
    if (!quiet) draw();
  }

  /* How far the arm's tool tip is from the move's point, when it is (a move between points, or
     joints and frames that disagree with the path). */
  function simOff(i, tip) {
    var p = [S.xyz[3 * i], S.xyz[3 * i + 1], S.xyz[3 * i + 2]];
    if (S.m.kind !== "arm" || !p.every(isFinite)) return "";
    var d = Math.hypot(tip[0] - p[0], tip[1] - p[1], tip[2] - p[2]);
    return d > 0.01 ? "; the tool tip is " + d.toFixed(2) + " mm from that point" : "";
  }

  /* The head's overlay (tip at 0, axis +Z) placed at tip with the axes u, v, a. */
  function simHeadMatrix(tip, u, v, a) {
    return new Float32Array([u[0], u[1], u[2], 0, v[0], v[1], v[2], 0, a[0], a[1], a[2], 0, tip[0], tip[1], tip[2], 1]);
  }

  function simActive() { return !!S && S.on; }

  /* The view of things in the tool path's frame: turned with the table (the view itself for an
     arm). */
  function simPart(v) {
    if (!simActive() || !S.model) return v;
    var m = S.model, e = v.eye;
    var eye = [m[0] * e[0] + m[1] * e[1] + m[2] * e[2], m[4] * e[0] + m[5] * e[1] + m[6] * e[2], m[8] * e[0] + m[9] * e[1] + m[10] * e[2]];
    return { mvp: simMul4(v.mvp, m), eye: eye, right: v.right, up: v.up };
  }

  function simDrawMesh(mesh, v, colour) {
    if (!mesh || mesh.n === 0) return;
    gl.useProgram(meshProg);
    gl.uniformMatrix4fv(gl.getUniformLocation(meshProg, "mvp"), false, v.mvp);
    gl.uniform3fv(gl.getUniformLocation(meshProg, "eye"), new Float32Array(v.eye));
    gl.uniform1f(gl.getUniformLocation(meshProg, "alpha"), 1);
    var mp = gl.getAttribLocation(meshProg, "pos"), mn = gl.getAttribLocation(meshProg, "nrm");
    /* One colour for the whole mesh: the colour attribute held constant. */
    var mc = gl.getAttribLocation(meshProg, "col");
    gl.disableVertexAttribArray(mc); gl.vertexAttrib3f(mc, colour[0], colour[1], colour[2]);
    gl.bindBuffer(gl.ARRAY_BUFFER, mesh.pos); gl.enableVertexAttribArray(mp); gl.vertexAttribPointer(mp, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, mesh.nrm); gl.enableVertexAttribArray(mn); gl.vertexAttribPointer(mn, 3, gl.FLOAT, false, 0, 0);
    gl.drawArrays(gl.TRIANGLES, 0, mesh.n);
    gl.disableVertexAttribArray(mn);
  }

  /* The machine, opaque: drawn right after the path. */
  function simDrawMachine(v, pv) {
    if (!simActive()) return;
    if (S.m.kind === "table") {
      simDrawMesh(S.turned, pv, S.orange);
      simDrawMesh(S.fixed, v, S.orange);
      drawOverlay(S.spokes, pv, [0, 0, 0, 0], [0.3, 0.12, 0.0, 0.9]);
    } else {
      simDrawMesh(S.links, v, S.orange);
    }
  }

  /* The head at the move, translucent (red at a colliding move). */
  function simDrawHead(v) {
    if (!simActive() || !S.head) return;
    var hit = (S.flags[S.cur] & 1) !== 0;
    drawOverlay(S.head, { mvp: simMul4(v.mvp, S.headAt) },
      hit ? [0.9, 0.2, 0.2, 0.22] : [0.3, 0.33, 0.38, 0.22], hit ? [0.7, 0.12, 0.12, 0.6] : [0.2, 0.22, 0.26, 0.6]);
  }

  /* The flagged moves and the current one, as dots over everything. */
  function simDrawDots(pv) {
    if (!simActive()) return;
    S.dots.forEach(function (g, k) { drawMarks(pv, g, 2, 3.5, S.flagColours[k]); });
    drawMarks(pv, S.dot, 2, 6.5, [0, 0, 0, 1]);
    drawMarks(pv, S.dot, 2, 4, [1, 1, 1, 1]);
  }

  /* The line vertices of the path drawn up to the current move (the rest is drawn faded), or
     -1 when the path is not split. */
  function simSplit(vert) {
    if (!simActive() || !P || !vert) return -1;
    var d = S.drawnAt[S.cur];
    return d < vert.length ? vert[d] : -1;
  }
