-- render_materials.lua: the materials other than links drawn by their strain, pixel by
-- pixel (r:draw's `materials` layer): a tet block's hull by its tets' volumetric strain,
-- a shape-matching cluster's particles by the cluster's strain, a pressure body's surface
-- by its volume against its target. Grey at rest, red expanded, blue compressed; with
-- materials = false the same scene shows none of it. Also w:stats() counting the types.

local W, H = 160, 120
local r = wobble.renderer{ width = W, height = H, samples = 4 }

local function at(p)
  local x, y = r:project(p[1], p[2], p[3])
  expect.truthy(x and x >= 0 and x < W and y >= 0 and y < H, "point inside the frame")
  return r:pixel(x, y)
end
local function is_grey(cr, cg, cb) return math.abs(cr - cg) < 20 and math.abs(cg - cb) < 20 and math.abs(cr - cb) < 25 end
local function rgb(cr, cg, cb) return "(" .. cr .. "," .. cg .. "," .. cb .. ")" end

-- every particle of a body scaled about c by s (per axis)
local function scale(w, ids, c, s)
  for _, id in ipairs(ids) do
    local x, y, z = w:position(id)
    w:set_position(id, c[1] + (x - c[1]) * s[1], c[2] + (y - c[2]) * s[2], c[3] + (z - c[3]) * s[3])
  end
end

local front = { 0, 1, 0.5 }   -- the middle of a unit block's front face (centre {0, 1, 0})

local function block(w, tets, young)
  return w:lattice{ min = {-0.5, 0.5, -0.5}, max = {0.5, 1.5, 0.5}, res = {3, 3, 3}, tets = tets, young = young }
end

test("a Neo-Hookean block shows det F - 1 like a volume block: blue squashed, red swollen", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local b = block(w, true, 1e5)
  expect.eq(w:stats().tets, w:tet_count()); expect.gt(w:tet_count(), 0); expect.eq(w:stats().volumes, 0)
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  scale(w, b.particles, {0, 1, 0}, {1, 1, 0.9})
  r:draw(w, { grid = false })
  local sr, sg, sb = at{ 0, 1, 0.45 }
  expect.gt(sb, sr + 60, "squashed: blue " .. rgb(sr, sg, sb))
  scale(w, b.particles, {0, 1, 0}, {1, 1, 1.1 / 0.9})
  r:draw(w, { grid = false })
  local er, eg, eb = at{ 0, 1, 0.55 }
  expect.gt(er, eb + 60, "swollen: red " .. rgb(er, eg, eb))
  -- a step projects every tet once per substep (no links: young makes none)
  local d = w:stats().distances
  w:step()
  expect.eq(w:stats().projections, 10 * (d + w:tet_count()))
end)

test("a tet block's hull shows its volumetric strain: grey at rest, blue squashed, red swollen", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local b = block(w, true)
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  r:draw(w, { grid = false })
  local cr, cg, cb = at(front)
  expect.truthy(is_grey(cr, cg, cb), "at rest: grey " .. rgb(cr, cg, cb))
  -- squashed 10 % along z (towards the camera's line: the face stays where it is
  -- drawn) : every tet's volume -10 %, no link stretched
  scale(w, b.particles, {0, 1, 0}, {1, 1, 0.9})
  local f = { 0, 1, 0.45 }
  r:draw(w, { grid = false })
  local sr, sg, sb = at(f)
  expect.gt(sb, sr + 60, "squashed: blue " .. rgb(sr, sg, sb))
  expect.gt(sb, cb, "bluer than at rest")
  r:draw(w, { grid = false, materials = false })
  local nr, ng, nb = at(f)
  expect.truthy(is_grey(nr, ng, nb), "materials = false: grey again " .. rgb(nr, ng, nb))
  -- swollen 10 % the other way: red
  scale(w, b.particles, {0, 1, 0}, {1, 1, 1.1 / 0.9})
  r:draw(w, { grid = false })
  local er, eg, eb = at{ 0, 1, 0.55 }
  expect.gt(er, eb + 60, "swollen: red " .. rgb(er, eg, eb)); expect.gt(er, eg + 60)
end)

test("a shape-matching cluster's particles show its strain", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local ids = {}
  for i = 0, 2 do
    for j = 0, 2 do ids[#ids + 1] = w:particle{ pos = { -0.5 + 0.5 * i, 0.5 + 0.5 * j, 0 }, mass = 1, radius = 0.2 } end
  end
  w:shape_match(ids)
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  local corner = { 0.5, 1.5, 0.15 }   -- on the sphere of the top right particle, facing us
  r:draw(w, { grid = false })
  local cr, cg, cb = at(corner)
  expect.truthy(is_grey(cr, cg, cb), "at rest: grey " .. rgb(cr, cg, cb))
  scale(w, ids, {0, 1, 0}, {1.2, 1.2, 1})   -- spread out 20 %
  local moved = { 0.6, 1.6, 0.15 }
  r:draw(w, { grid = false })
  local er, eg, eb = at(moved)
  expect.gt(er, eb + 60, "spread: red " .. rgb(er, eg, eb))
  r:draw(w, { grid = false, materials = false })
  local nr, _, nb = at(moved)
  expect.gt(nb, nr + 40, "materials = false: the particles' own blue " .. rgb(nr, 0, nb))
  scale(w, ids, {0, 1, 0}, {0.8 / 1.2, 0.8 / 1.2, 1})   -- drawn in 20 %
  r:draw(w, { grid = false })
  local sr, sg, sb = at{ 0.4, 1.4, 0.15 }
  expect.gt(sb, sr + 60, "drawn in: blue " .. rgb(sr, sg, sb))
  expect.truthy(not is_grey(sr, sg, sb) and sb > cb, "bluer than at rest")
end)

test("a pressure body's surface shows its volume against pressure x V0", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local b = block(w, false)
  local p = w:pressure(b)
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  r:draw(w, { grid = false })
  local cr, cg, cb = at(front)
  expect.truthy(is_grey(cr, cg, cb), "at its target: grey " .. rgb(cr, cg, cb))
  p:set_pressure(1.25)   -- wants 25 % more than it has: under-inflated, blue
  r:draw(w, { grid = false })
  local sr, sg, sb = at(front)
  expect.gt(sb, sr + 60, "under-inflated: blue " .. rgb(sr, sg, sb))
  r:draw(w, { grid = false, materials = false })
  expect.truthy(is_grey(at(front)), "materials = false: grey")
  p:set_pressure(0.8)    -- holds 25 % more than it wants: red
  r:draw(w, { grid = false })
  local er, eg, eb = at(front)
  expect.gt(er, eb + 60, "over-inflated: red " .. rgb(er, eg, eb))
end)

test("r:draw's materials option is checked", function()
  local w = wobble.world{}
  expect.error(function() r:draw(w, { materials = 1 }) end, "materials")
  expect.error(function() r:draw(w, { material = true }) end, "material")
end)

test("w:stats() counts every type and every type's projections", function()
  local w = wobble.world{ substeps = 4, gravity = {0, 0, 0} }
  local b = block(w, true)
  local s = w:stats()
  expect.eq(s.volumes, w:volume_count())
  expect.gt(s.volumes, 0)
  expect.eq(s.bends, 0); expect.eq(s.shape_matches, 0); expect.eq(s.pressures, 0)
  w:shape_match(b)
  w:pressure(b)
  s = w:stats()
  expect.eq(s.shape_matches, 1); expect.eq(s.pressures, 1)
  w:step()
  -- per substep: every link, every tet, one cluster, one pressure body
  expect.eq(w:stats().projections, 4 * (s.distances + s.volumes + 2))
end)
