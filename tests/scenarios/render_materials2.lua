-- render_materials2.lua: the materials layer draws every type: a bend by its
-- angle off its rest at its hinge (red bent further, blue opened flatter, full at pi/4),
-- a Neo-Hookean tet by its shape change as well as its volume change (a shear keeps
-- det F = 1 yet strains the material). Pixel by pixel, as render_materials.lua.

local W, H = 160, 120
local r = wobble.renderer{ width = W, height = H, samples = 4 }

local function at(p)
  local x, y = r:project(p[1], p[2], p[3])
  expect.truthy(x and x >= 0 and x < W and y >= 0 and y < H, "point inside the frame")
  return r:pixel(x, y)
end
local function is_grey(cr, cg, cb) return math.abs(cr - cg) < 20 and math.abs(cg - cb) < 20 and math.abs(cr - cb) < 25 end
local function rgb(cr, cg, cb) return "(" .. cr .. "," .. cg .. "," .. cb .. ")" end

-- a 2 x 1 cloth standing in the xy plane (x -1..1, y 0.5..1.5, vertices 0.25 apart),
-- facing the camera; made flat (its bends rest at 0) and stood up rigidly
local function standing_cloth(w, bend)
  local cloth = w:cloth{ origin = {-1, 0.5, 0}, size = {2, 1}, res = {9, 5}, bend = bend }
  for _, id in ipairs(cloth.particles) do
    local x, _, z = w:position(id)
    w:set_position(id, x, 0.5 + z, 0)
  end
  return cloth
end
local function find(w, cloth, x, y)
  for _, id in ipairs(cloth.particles) do
    local px, py = w:position(id)
    if math.abs(px - x) < 1e-6 and math.abs(py - y) < 1e-6 then return id end
  end
  error("no particle at " .. x .. ", " .. y)
end

local fold, away = { 0, 1, 0 }, { -0.75, 1, 0 }

test("a bent cloth folded shows colour at the fold, grey where flat and with materials = false", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local cloth = standing_cloth(w, true)
  expect.gt(w:stats().bends, 0)
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  r:draw(w, { grid = false })
  local cr, cg, cb = at(fold)
  expect.truthy(is_grey(cr, cg, cb), "flat: grey at the fold-to-be " .. rgb(cr, cg, cb))
  -- fold the right half 60 degrees towards the camera about the line x = 0 (rigidly:
  -- no link stretched, every bend on the line pi/3 off its rest of 0)
  local th = math.pi / 3
  for _, id in ipairs(cloth.particles) do
    local x, y = w:position(id)
    if x > 1e-9 then w:set_position(id, x * math.cos(th), y, x * math.sin(th)) end
  end
  r:draw(w, { grid = false })
  local fr, fg, fb = at(fold)
  expect.gt(fr, fb + 60, "folded: red at the fold " .. rgb(fr, fg, fb)); expect.gt(fr, fg + 60)
  local ar, ag, ab = at(away)
  expect.truthy(is_grey(ar, ag, ab), "folded: grey away from the fold " .. rgb(ar, ag, ab))
  r:draw(w, { grid = false, materials = false })
  local nr, ng, nb = at(fold)
  expect.truthy(is_grey(nr, ng, nb), "materials = false: grey at the fold " .. rgb(nr, ng, nb))
  -- the same fold with no bends: nothing to show
  local w2 = wobble.world{ gravity = {0, 0, 0} }
  local plain = standing_cloth(w2, nil)
  expect.eq(w2:stats().bends, 0)
  for _, id in ipairs(plain.particles) do
    local x, y = w2:position(id)
    if x > 1e-9 then w2:set_position(id, x * math.cos(th), y, x * math.sin(th)) end
  end
  r:draw(w2, { grid = false })
  expect.truthy(is_grey(at(fold)), "no bends: grey")
end)

test("a bend opened flatter than its rest shows blue at its hinge", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local cloth = standing_cloth(w, nil)
  -- hinge (0, 1)-(0, 1.25), wings either side; it wants 1 rad but lies flat
  local b = w:bend(find(w, cloth, 0, 1), find(w, cloth, 0, 1.25), find(w, cloth, -0.25, 1), find(w, cloth, 0.25, 1.25),
    { rest = 1.0 })
  expect.near(b:angle(), 0, 1e-9)
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  r:draw(w, { grid = false })
  local sr, sg, sb = at(fold)
  expect.gt(sb, sr + 60, "flatter than its rest: blue " .. rgb(sr, sg, sb))
  expect.truthy(is_grey(at(away)), "away from the hinge: grey")
end)

test("a Neo-Hookean block sheared (volume kept) is no longer grey", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local b = w:lattice{ min = {-0.5, 0.5, -0.5}, max = {0.5, 1.5, 0.5}, res = {3, 3, 3}, tets = true, young = 1e5 }
  expect.gt(w:tet_count(), 0)
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  local front = { 0, 1, 0.5 }   -- on the line y = 1 the shear leaves in place
  r:draw(w, { grid = false })
  local cr, cg, cb = at(front)
  expect.truthy(is_grey(cr, cg, cb), "at rest: grey " .. rgb(cr, cg, cb))
  -- x += k (y - 1): det F = 1 exactly, every tet sheared by k
  local k = 0.1
  for _, id in ipairs(b.particles) do
    local x, y, z = w:position(id)
    w:set_position(id, x + k * (y - 1), y, z)
  end
  for i = 1, w:tet_count() do
    expect.near(w:tet_info(i), 1, 1e-9)
  end
  r:draw(w, { grid = false })
  local sr, sg, sb = at(front)
  expect.gt(sr, sb + 60, "sheared: red " .. rgb(sr, sg, sb)); expect.gt(sr, sg + 60)
  r:draw(w, { grid = false, materials = false })
  local nr, ng, nb = at(front)
  expect.truthy(is_grey(nr, ng, nb), "materials = false: grey " .. rgb(nr, ng, nb))
end)
