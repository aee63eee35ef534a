-- residual.lua: w:stats().residual, the constraints' residual, and the world's tolerance
-- (the iterations stop once the residual is at most it).
--
-- The residual of an XPBD constraint is what its projection drives to zero, |C + alpha~
-- lambda| (alpha~ = compliance / h^2, lambda the substep's multiplier), over the RMS of its
-- corners' gradients: metres, how far its corners are from meeting it. The world's
-- residual is the largest over every constraint, after the last substep's iterations
-- (before the contacts move anything), measured by every step once it has been read.
--
-- What is checked, each from XPBD's own algebra (no number copied from a run):
--  1. One constraint alone is met by one projection: a link of rest length L holding a
--     mass under a pin. Hard: C = 0 to round-off. Compliant (alpha): it hangs stretched
--     by C = m g alpha (the spring of stiffness 1/alpha), yet C + alpha~ lambda = 0, so
--     the residual is round-off while C is not: the residual is not the stretch.
--  2. Many constraints are met only as the iterations converge: a strip of 21 x 3
--     particles (hard links, bends of compliance 0.2) clamped at one end, after 1 s from
--     flat. Gauss-Seidel converges, so the residual falls with the iterations: 1 > 10 >
--     100, and at 100 it is below 1% of 1 iteration's.
--  3. tolerance: the same strip at up to 100 iterations with tolerance = the 10-iteration
--     residual stops early (fewer projections than 100 iterations) and ends with a
--     residual of at most ~ the tolerance (checked after iterations 1-4, each 4th and the
--     last, so up to 3 iterations past the one that reached it; the step's
--     velocity update and later substeps move nothing the constraints see: 1.5x room).
--  4. The switch-off: with the residual reporting 0 or the tolerance ignored, 2 and 3 fail.

local function hanging(compliance)
  -- (drag on the velocity only, so the bob comes to rest where the spring holds it)
  local w = wobble.world{ substeps = 10, damping = 10 }
  local a = w:particle{ pos = { 0, 1, 0 }, mass = 1 }
  local b = w:particle{ pos = { 0, 0.5, 0 }, mass = 2 }
  w:distance(a, b, { compliance = compliance })
  w:pin(a)
  local _ = w:stats().residual -- (read once: from now on each step measures it)
  for _ = 1, 120 do w:step() end
  local _, y = w:position(b)
  return w, 1 - y - 0.5
end

test("one link is met by one projection: residual 0 while a compliant one is stretched", function()
  local w, stretch = hanging(0)
  expect.lt(math.abs(stretch), 1e-9, "a hard link's stretch")
  expect.lt(w:stats().residual, 1e-9, "its residual")
  local alpha = 1e-3
  local w2, s2 = hanging(alpha)
  -- at rest the spring carries m g: stretch m g alpha = 2 * 9.81 * 1e-3 (1% room: what is
  -- left of its ringing after 2 s at a drag of 10/s)
  expect.near(s2, 2 * 9.81 * alpha, 0.01 * 2 * 9.81 * alpha, "a compliant link's stretch")
  expect.lt(w2:stats().residual, 1e-9, "its residual (C + alpha~ lambda)")
end)

local function strip(iterations, tolerance)
  local w = wobble.world{ substeps = 10, iterations = iterations, tolerance = tolerance }
  local c = w:cloth{ origin = { 0, 1, 0 }, size = { 1, 0.1 }, res = { 21, 3 }, compliance = 0, bend = 0.2, mass = 0.1 }
  for _, p in ipairs(c.particles) do
    if w:position(p) < 0.06 then w:pin(p) end -- two columns: clamped, not hinged
  end
  local projections, _ = 0, w:stats().residual
  for _ = 1, 60 do
    w:step()
    projections = projections + w:stats().projections
  end
  return w:stats().residual, projections, w:stats().iterations_run
end

test("the residual falls as the iterations converge", function()
  local r1, r10, r100 = strip(1), strip(10), strip(100)
  print(string.format("# strip residual: 1 it %.3g m, 10 it %.3g m, 100 it %.3g m", r1, r10, r100))
  expect.gt(r1, r10, "1 iteration leaves more than 10")
  expect.gt(r10, r100, "10 leave more than 100")
  expect.lt(r100, 0.01 * r1, "100 leave under 1% of 1's")
end)

test("tolerance stops the iterations early", function()
  local tol = strip(10)
  local _, full, all = strip(100)
  local r, p, ran = strip(100, tol)
  print(string.format("# tolerance %.3g m: residual %.3g m, %d projections (100 iterations: %d), %.1f iterations a substep",
                      tol, r, p, full, ran))
  expect.lt(p, full, "fewer projections than every iteration")
  expect.lt(r, 1.5 * tol, "a residual of about the tolerance")
  -- w:stats().iterations_run: what the substeps ran, on average (the setting stays 100)
  expect.eq(all, 100, "iterations run without a tolerance")
  expect.lt(ran, 100, "iterations run with it")
  expect.gt(ran, 1, "... more than one: the tolerance is the 10-iteration residual")
end)

test("tolerance must be a finite number >= 0", function()
  local ok, err = pcall(wobble.world, { tolerance = -1 })
  expect.eq(ok, false, "a negative tolerance is refused")
  expect.truthy(tostring(err):find("tolerance"), "the error names the option: " .. tostring(err))
  local w = wobble.world{}
  w:set_tolerance(1e-4)
  expect.eq(w:tolerance(), 1e-4, "set_tolerance / tolerance")
end)

-- 5. Every constraint type reports: a lattice block dropped on the ground, each with one
-- kind of constraint holding it (volume constraints, Neo-Hookean tets, a compliant shape
-- match, a pressure over soft links): its residual after the landing is > 0 at 1 iteration
-- and at 30 iterations is below a tenth of it (Gauss-Seidel converging). A type whose
-- residual hook reported nothing would fail the first check.
local function block(kind, iterations)
  local w = wobble.world{ substeps = 10, iterations = iterations }
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0 }
  local opts = { min = { 0, 0.15, 0 }, max = { 0.6, 0.75, 0.6 }, res = { 4, 4, 4 }, mass = 1 }
  if kind == "volume" then opts.tets, opts.compliance = true, 1e-3 end
  if kind == "tet" then opts.tets, opts.young = true, 1e4 end
  if kind ~= "volume" and kind ~= "tet" then opts.compliance = tonumber(wobble.args.lc or 1e-3) end
  local b = w:lattice(opts)
  if kind == "shape" then w:shape_match(b, { stiffness = tonumber(wobble.args.ss or 0.5) }) end
  if kind == "pressure" then w:pressure(b, { pressure = 1, compliance = 1e-6 }) end
  local _ = w:stats().residual
  for _ = 1, 20 do w:step() end
  return w:stats().residual
end

test("every constraint type has a residual, which falls with the iterations", function()
  for _, kind in ipairs{ "volume", "tet", "shape", "pressure" } do
    local r1, r30 = block(kind, 1), block(kind, 30)
    print(string.format("# %s: residual 1 it %.3g m, 30 it %.3g m", kind, r1, r30))
    expect.gt(r1, 0, kind .. ": a residual at 1 iteration")
    expect.lt(r30, 0.1 * r1, kind .. ": 30 iterations leave under a tenth")
  end
end)

-- 6. Attachments and grabs: a particle hanging from a compliant attachment (to a sphere
-- collider) and one held by a compliant grab are each met by their one
-- projection, as the link of 1: residual round-off, while each hangs m g alpha off (the
-- attachment holds the point where the particle was made, 2 m under its sphere).
test("attachments and grabs report their residual", function()
  for _, kind in ipairs{ "attach", "grab" } do
    local w = wobble.world{ damping = 10, contacts = false }
    local p = w:particle{ pos = { 0, 1, 0 }, mass = 2 }
    if kind == "attach" then
      local c = w:collider{ shape = "sphere", center = { 0, 3, 0 }, radius = 0.1 } -- (held 2 m below it)
      w:attach(p, c, { compliance = 1e-3 })
    else
      w:grab(p, { 0, 1, 0 }, { compliance = 1e-3 })
    end
    local r0 = w:stats().residual
    for _ = 1, 120 do w:step() end
    local _, y = w:position(p)
    expect.eq(r0, 0, kind .. ": nothing before the first step")
    expect.near(1 - y, 2 * 9.81 * 1e-3, 0.01 * 2 * 9.81 * 1e-3, kind .. ": hangs m g alpha low")
    expect.lt(w:stats().residual, 1e-9, kind .. ": its residual")
  end
end)
