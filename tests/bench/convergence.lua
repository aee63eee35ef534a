-- convergence.lua: error against CPU time for the two solvers (XPBD Gauss-Seidel and VBD),
-- and the cost of one VBD iteration against one XPBD iteration on the 128 x 128 cloth.
-- Three scenes, each at 10 substeps and 1, 2, 4, ... iterations, both solvers:
--   strip  the 1 m cloth strip (21 x 3, links compliance 0, bends 0.2 rad/(N m)) clamped at
--          one end, 600 frames with a drag (damping 2) so it settles; error: its droop off the
--          converged droop (XPBD 10 x 100), relative;
--   bar    the Neo-Hookean bar of E = 1e7 Pa (1 m, 0.1 x 0.1 m, 1 kg, 3 x 21 x 3 particles)
--          hanging from its top face, 300 frames with a drag (20); error: its elongation off
--          rho g L^2 / 2E = 0.049 mm, relative (capped at 10: a collapsed bar);
--   cloth  the 128 x 128 cloth of cloth128.lua (rigid structural and shear links) pinned at
--          two corners, 60 frames from flat; error: the largest strain at the end.
-- CPU time: the solver's ms per frame (w:stats().solve_ms, the median over the frames). The cost of an iteration: the
-- cloth's solve time at 9 iterations less that at 1, over 8, per substep, each solver (the
-- fixed cost of a substep, the prediction and the sweep's set-up, drops out).
-- --set plot=FILE.png draws the error against ms per frame (log-log) with ffmpeg (the
-- recorder's encoder; needs --unsafe); --set quick=1 runs only 1 and 2 iterations and 2
-- frames of each (the check that the scene runs).
-- Run: make bench   (or build/wobble bench --unsafe --set scenes=convergence [--set plot=out/c.png])
local bench = require("wobble.bench")
local args = wobble.args
if not bench.want("convergence") then return end
local quick = args.quick == 1 or args.frames ~= nil
local ITERS = quick and { 1, 2 } or { 1, 2, 4, 8, 16, 32 }
local CLOTH_ITERS = quick and { 1, 2 } or { 1, 2, 4, 8 }
local function frames(n) return args.frames ~= nil and bench.frames(n) or quick and 2 or n end
local G = 9.81

-- the median of the frames' solve times (a busy machine's hiccups left out)
local function solve_ms(w, n)
  local t = {}
  for k = 1, n do
    w:step()
    t[k] = w:stats().solve_ms
  end
  table.sort(t)
  return n % 2 == 1 and t[(n + 1) // 2] or (t[n // 2] + t[n // 2 + 1]) / 2
end

local function strip(solver, iters)
  local w = wobble.world{ solver = solver, substeps = 10, iterations = iters, damping = 2 }
  local c = w:cloth{ origin = { 0, 1, 0 }, size = { 1, 0.1 }, res = { 21, 3 }, compliance = 0, bend = 0.2, mass = 0.1 }
  for _, p in ipairs(c.particles) do
    if w:position(p) < 0.06 then w:pin(p) end
  end
  local ms = solve_ms(w, frames(600))
  local low = 1
  for _, p in ipairs(c.particles) do
    local _, y = w:position(p)
    low = math.min(low, y)
  end
  return 1 - low, ms
end

local function bar(solver, iters)
  local w = wobble.world{ solver = solver, substeps = 10, iterations = iters, damping = 20 }
  local b = w:lattice{ min = { 0, 0, 0 }, max = { 0.1, 1, 0.1 }, res = { 3, 21, 3 }, mass = 1, tets = true, young = 1e7,
                       poisson = 0.3 }
  local bottom = {}
  for _, p in ipairs(b.particles) do
    local _, y = w:position(p)
    if y > 0.999 then w:pin(p) end
    if y < 0.001 then bottom[#bottom + 1] = p end
  end
  local ms = solve_ms(w, frames(300))
  local s = 0
  for _, p in ipairs(bottom) do
    local _, y = w:position(p)
    s = s + y / #bottom
  end
  return -s, ms
end

local function cloth(solver, iters, n)
  local w = wobble.world{ solver = solver, substeps = 10, iterations = iters }
  local c = w:cloth{ origin = { -1, 1, -1 }, size = { 2, 2 }, res = { 128, 128 }, mass = 1, shear = true }
  w:pin(c.particles[1])
  w:pin(c.particles[128])
  w:step() -- (the first step colours the constraints: not timed)
  local ms = solve_ms(w, n)
  local st = w:stats()
  return w:max_strain(), ms, st.substeps, st.distances
end

local series = {} -- { name, solver, points = { {ms, err, iters} } }
local function add(name, solver, ms, err, it)
  local key = name .. " " .. solver
  if not series[key] then
    series[key] = { name = name, solver = solver, points = {} }
    series[#series + 1] = series[key]
  end
  local p = series[key].points
  p[#p + 1] = { ms, err, it }
end

local SOLVERS = { "gauss-seidel", "vbd" }
local ref = strip("gauss-seidel", quick and 2 or 100)
local want_bar = 100 * G / (2 * 1e7)
for _, solver in ipairs(SOLVERS) do
  for _, it in ipairs(ITERS) do
    local d, ms = strip(solver, it)
    add("strip", solver, ms, math.abs(d - ref) / ref, it)
    local e, ms2 = bar(solver, it)
    add("bar", solver, ms2, math.min(10, math.abs(e - want_bar) / want_bar), it)
  end
  for _, it in ipairs(CLOTH_ITERS) do
    local s, ms, _, links = cloth(solver, it, frames(60))
    add("cloth", solver, ms, s, it)
    series.links = links
  end
end

-- the cost of one iteration on the cloth (per substep): solve time at 9 iterations less at 1
local per_iter = {}
for _, solver in ipairs(SOLVERS) do
  local n = frames(20)
  local _, t1, sub = cloth(solver, 1, n)
  local _, t9 = cloth(solver, 9, n)
  per_iter[solver] = (t9 - t1) / (8 * sub)
end

-- (--json: the row alone, one JSON object a line)
local say = args.json and function() end or print
for _, s in ipairs(series) do
  local row = {}
  for _, p in ipairs(s.points) do row[#row + 1] = string.format("%dx: %.3g ms %.3g", p[3], p[1], p[2]) end
  say(string.format("# %-5s %-12s %s", s.name, s.solver, table.concat(row, " | ")))
end
say(string.format("# strip converged droop %.4f m (XPBD 10 x 100); bar's analytic elongation %.4f mm", ref, 1e3 * want_bar))
local ratio = per_iter.vbd / per_iter["gauss-seidel"]
say(string.format("# cloth 128 x 128: one iteration of a substep %.3f ms XPBD, %.3f ms VBD (%.2fx)", per_iter["gauss-seidel"],
                    per_iter.vbd, ratio))

-- ---- the plot: a PPM drawn here, made a PNG by ffmpeg ----------------------------------------
local function plot(path)
  local W, H, L, R, T, B = 800, 560, 60, 20, 20, 40
  local px = {}
  for i = 1, W * H * 3 do px[i] = 255 end
  local function put(x, y, c)
    x, y = math.floor(x + 0.5), math.floor(y + 0.5)
    if x < 0 or y < 0 or x >= W or y >= H then return end
    local i = (y * W + x) * 3
    px[i + 1], px[i + 2], px[i + 3] = c[1], c[2], c[3]
  end
  local function line(x0, y0, x1, y1, c, thick)
    local n = math.max(1, math.ceil(math.max(math.abs(x1 - x0), math.abs(y1 - y0))))
    for k = 0, n do
      local x, y = x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n
      for dx = 0, thick - 1 do for dy = 0, thick - 1 do put(x + dx, y + dy, c) end end
    end
  end
  local xmin, xmax, ymin, ymax = math.huge, -math.huge, math.huge, -math.huge
  for _, s in ipairs(series) do
    for _, p in ipairs(s.points) do
      local lx, ly = math.log(p[1], 10), math.log(math.max(p[2], 1e-9), 10)
      xmin, xmax, ymin, ymax = math.min(xmin, lx), math.max(xmax, lx), math.min(ymin, ly), math.max(ymax, ly)
    end
  end
  xmin, xmax, ymin, ymax = math.floor(xmin), math.ceil(xmax), math.floor(ymin), math.ceil(ymax)
  if xmax == xmin then xmax = xmin + 1 end
  if ymax == ymin then ymax = ymin + 1 end
  local function X(v) return L + (math.log(v, 10) - xmin) / (xmax - xmin) * (W - L - R) end
  local function Y(v) return H - B - (math.log(math.max(v, 1e-9), 10) - ymin) / (ymax - ymin) * (H - T - B) end
  local grey, black = { 210, 210, 210 }, { 0, 0, 0 }
  for d = xmin, xmax do line(X(10 ^ d), T, X(10 ^ d), H - B, grey, 1) end
  for d = ymin, ymax do line(L, Y(10 ^ d), W - R, Y(10 ^ d), grey, 1) end
  line(L, H - B, W - R, H - B, black, 1)
  line(L, T, L, H - B, black, 1)
  -- colours: strip blue, bar red, cloth green; XPBD pale and thin, VBD dark and thick
  local hue = { strip = { { 140, 170, 235 }, { 20, 60, 200 } }, bar = { { 240, 150, 140 }, { 200, 30, 20 } },
                cloth = { { 140, 215, 140 }, { 20, 130, 30 } } }
  for _, s in ipairs(series) do
    local v = s.solver == "vbd"
    local c, th = hue[s.name][v and 2 or 1], v and 3 or 2
    for k, p in ipairs(s.points) do
      local x, y = X(p[1]), Y(p[2])
      for dx = -3, 3 do for dy = -3, 3 do put(x + dx, y + dy, c) end end
      if k > 1 then line(X(s.points[k - 1][1]), Y(s.points[k - 1][2]), x, y, c, th) end
    end
  end
  -- the decades' exponents (3 x 5 digits, drawn twice as large): "1" under a tick is 10^1
  local glyph = { ["0"] = "111101101101111", ["1"] = "010110010010111", ["2"] = "111001111100111",
                  ["3"] = "111001111001111", ["4"] = "101101111001001", ["5"] = "111100111001111",
                  ["6"] = "111100111101111", ["7"] = "111001001001001", ["8"] = "111101111101111",
                  ["9"] = "111101111001111", ["-"] = "000000111000000" }
  local function text(x, y, str)
    for k = 1, #str do
      local gl = glyph[str:sub(k, k)]
      for r = 0, 4 do for c = 0, 2 do
        if gl:sub(r * 3 + c + 1, r * 3 + c + 1) == "1" then
          for a = 0, 1 do for b = 0, 1 do put(x + (k - 1) * 8 + 2 * c + a, y + 2 * r + b, black) end end
        end
      end end
    end
  end
  for d = xmin, xmax do text(X(10 ^ d) - 4 * #tostring(d), H - B + 8, tostring(d)) end
  for d = ymin, ymax do text(L - 8 - 8 * #tostring(d), Y(10 ^ d) - 5, tostring(d)) end
  local ppm = path:gsub("%.png$", "") .. ".ppm"
  local f = assert(io.open(ppm, "wb"))
  f:write(string.format("P6\n%d %d\n255\n", W, H))
  local chunk = {}
  for i = 1, #px do
    chunk[#chunk + 1] = string.char(px[i])
    if #chunk == 4096 then f:write(table.concat(chunk)); chunk = {} end
  end
  f:write(table.concat(chunk))
  f:close()
  assert(os.execute(string.format("ffmpeg -loglevel error -y -i '%s' '%s'", ppm, path)), "ffmpeg failed")
  os.remove(ppm)
  say(string.format("# plot: %s (x: solve ms per frame, 10^%d to 10^%d; y: error, 10^%d to 10^%d)", path, xmin, xmax,
                      ymin, ymax))
end
if args.plot then plot(tostring(args.plot)) end

-- the row: the cloth under VBD at 10 x 1 (ns per projection: per link and iteration, the
-- solver's time alone, so both columns are the same)
local v1, cms = series["strip vbd"].points[1], series["cloth vbd"].points[1][1]
local ns = cms * 1e6 / (10 * series.links)
bench.report({
  scene = "convergence", particles = 128 * 128, constraints = series.links, substeps = 10, iterations = 1, threads = 1,
  frames = frames(60), ms_per_frame = cms, ns_per_projection = ns, ns_per_projection_solve = ns, bytes_per_particle = bench.null,
  vbd_iteration_ms = per_iter.vbd, xpbd_iteration_ms = per_iter["gauss-seidel"], vbd_over_xpbd_iteration = ratio,
  strip_vbd_error_10x1 = v1[2], strip_xpbd_error_10x1 = series["strip gauss-seidel"].points[1][2],
}, string.format("cloth VBD 10 x 1; one VBD iteration %.2fx one XPBD's; strip at 10 x 1 %.0f%% off (XPBD %.0f%%)", ratio,
                 100 * v1[2], 100 * series["strip gauss-seidel"].points[1][2]))
