-- A tet block squeezed slowly by a kinematic box collider to about 60% of its height,
-- held, and released. Physics: a press moving at 0.1 m/s deforms an elastic block
-- quasi-statically, so its particles move at about the press's speed (the bulge's sides
-- a fraction of it): nothing should move faster than 1 m/s (10x the press). The
-- block springs back when released. If the solve does go wrong, w:warnings() must say so.
-- Two ways a user makes a tet block: Neo-Hookean (young/poisson) and volume tets with
-- soft links (as scripts/block_jelly.lua). Block placed r above the ground as the README
-- advises (a block made inside the ground is the other test's subject).
local S, RES = 0.4, 5                    -- 0.4 m cube, spacing 0.1, default radius r = 0.05
local r = S / (RES - 1) / 2
local SPEED = 0.1                        -- the press's speed (m/s)
local TARGET = 0.6                       -- squeeze to 60% of the height

local radius_ok = true
local function run(label, opts)
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0, friction = 0.5 }
  opts.min, opts.max, opts.res = { -S / 2, r, -S / 2 }, { S / 2, r + S, S / 2 }, { RES, RES, RES }
  local b = w:lattice(opts)
  -- the README promises a default radius of half the spacing; check it, then go on with
  -- the radius the body really has (moved to rest on the ground by it), so the squeeze is
  -- tested on its own
  local rr = w:radius(b.particles[1])
  radius_ok = radius_ok and math.abs(rr - r) < 1e-12
  print(string.format("%s: default contact radius %.4f (README: half the spacing, %.4f)", label, rr, r))
  for _, p in ipairs(b.particles) do local x, y, z = w:position(p); w:set_position(p, x, y + rr - r, z) end
  local half = 0.1
  local face0 = rr + S + rr + 0.02               -- the press's face 2 cm above the block's top sphere
  local face_low = rr + TARGET * S + rr          -- the face where the top particles are at 60%
  local t_down = (face0 - face_low) / SPEED
  local t_hold = t_down + 1.0
  local press = w:collider{ shape = "box", center = { 0, face0 + half, 0 }, half = { 0.6, half, 0.6 }, friction = 0.5 }
  local max_speed, min_h, inside, below, t_fast = 0, math.huge, 0, math.huge, nil
  local deep_strain, deep_vol = 0, nil
  w:run{ seconds = t_hold + 2.5, on_frame = function(w, f, t)
    local face = t < t_down and face0 - SPEED * t or (t < t_hold and face_low or face_low + SPEED * (t - t_hold))
    press:set_position(0, face + half, 0)
    local _, miny, _, _, maxy = w:bounds()
    if maxy - miny < min_h then
      deep_strain = w:max_strain()
      if w:volume_count() > 0 then local v, v0 = w:total_volume(); deep_vol = v / v0 end
    end
    min_h = math.min(min_h, maxy - miny)
    below = math.min(below, miny)
    for _, p in ipairs(b.particles) do
      local vx, vy, vz = w:velocity(p)
      local s = math.sqrt(vx * vx + vy * vy + vz * vz)
      if s > max_speed then max_speed = s; if s > 1 then t_fast = t_fast or t end end
      local x, y, z = w:position(p)
      if press:distance(x, y, z) < w:radius(p) - 2e-3 then inside = inside + 1 end
    end
  end }
  local _, miny, _, _, maxy = w:bounds()
  local nwarn, msg = w:warnings()
  print(string.format("%s: at the deepest press: links' max strain %.3f%s", label, deep_strain,
    deep_vol and string.format(", volume %.3f of rest", deep_vol) or ""))
  print(string.format("%s: squeezed to %.3f of its height (aim %.2f), back to %.3f; max particle speed %.2f m/s%s; "
    .. "particle-frames inside the press %d; lowest particle %.4f; warnings %d %s", label, min_h / S, TARGET,
    (maxy - miny) / S, max_speed, t_fast and string.format(" (first over 1 m/s at t = %.2f s)", t_fast) or "",
    inside, below, nwarn, msg or ""))
  expect.lt(min_h / S, TARGET + 0.05, "squeezed to about 60%")
  expect.lt(max_speed, 1.0, "no particle faster than 1 m/s under a 0.1 m/s press")
  expect.truthy(max_speed < 1.0 or nwarn > 0, "a blow-up is reported by w:warnings()")
  expect.eq(inside, 0, "no particle inside the press (by more than 2 mm)")
  expect.gt(below, rr - 5e-3, "no particle in the ground")
  -- elastic: springs back to its height within 5% (sag under its weight is under 1%)
  expect.gt((maxy - miny) / S, 0.95, "springs back")
end

test("Neo-Hookean lattice (young = 1e5, poisson = 0.3) squeezed slowly to 60% and released", function()
  run("neo-hookean", { tets = true, young = 1e5, poisson = 0.3, mass = 64 })   -- 1000 kg/m^3
end)

test("volume-tet lattice with soft links (a jelly) squeezed slowly to 60% and released", function()
  run("volume tets", { tets = true, compliance = 1e-3, mass = 2 })
end)

test("w:lattice{tets = true} with every default (rigid links, incompressible tets) squeezed slowly to 60%", function()
  -- rigid links cannot be shortened and the tets keep their volume: the press asks the
  -- impossible, but a slow press must not make the block explode, and if the solve
  -- cannot cope, w:warnings() says so
  run("default tets", { tets = true, mass = 2 })
end)

test("Neo-Hookean lattice, stiffer (young = 1e6), squeezed slowly to 60% and released", function()
  -- the README: the substep must stay under the time a wave crosses the smallest tet;
  -- sqrt(1e6 / 1000) = 32 m/s over 0.1 m is 3 ms, h = 1.7 ms at the default substeps
  run("neo-hookean 1e6", { tets = true, young = 1e6, poisson = 0.3, mass = 64 })
end)

test("every tet lattice above got the README's default contact radius (half the spacing)", function()
  expect.truthy(radius_ok, "default radius = half the spacing for every lattice above")
end)
