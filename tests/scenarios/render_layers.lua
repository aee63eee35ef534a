-- render_layers.lua: what the layers show of a body's state, pixel by pixel: a surface
-- coloured by its links' stretch (grey at rest, red stretched, as the reference
-- thesis's Figure 12), and a skin hiding the cage it is bound to.

local W, H = 160, 120
local r = wobble.renderer{ width = W, height = H, samples = 4 }

local function at(p)
  local x, y = r:project(p[1], p[2], p[3])
  expect.truthy(x and x >= 0 and x < W and y >= 0 and y < H, "point inside the frame")
  return r:pixel(x, y)
end

local function is_grey(cr, cg, cb) return math.abs(cr - cg) < 20 and math.abs(cg - cb) < 20 and math.abs(cr - cb) < 25 end
local function is_sky(cr, _, cb) return cb > cr + 20 end

-- a 2 x 1 cloth standing in the xy plane (x -1..1, y 0.5..1.5), facing the camera
local function standing_cloth(w, res)
  local cloth = w:cloth{ origin = {-1, 0.5, 0}, size = {2, 1}, res = res }
  for _, id in ipairs(cloth.particles) do
    local x, _, z = w:position(id)
    w:set_position(id, x, 0.5 + z, 0)
  end
  return cloth
end

test("with links drawn, a surface is grey at rest and red where stretched", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local cloth = standing_cloth(w, {9, 5})   -- columns 0.25 apart
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  r:draw(w, { grid = false })
  local cr, cg, cb = at{ 0.08, 1.04, 0 }   -- between links: the surface itself
  expect.truthy(is_grey(cr, cg, cb) and cr > 100, "at rest: a neutral grey (" .. cr .. "," .. cg .. "," .. cb .. ")")
  -- stretch the last column by 0.1 (40 % on the links to it): red there, grey in the middle
  local right = {}
  for _, id in ipairs(cloth.particles) do
    local x, y, z = w:position(id)
    if x > 0.99 then right[#right + 1] = { id, x, y, z } end
  end
  expect.eq(#right, 5)
  local function shift(dx)
    for _, p in ipairs(right) do w:set_position(p[1], p[2] + dx, p[3], p[4]) end
  end
  shift(0.1)
  r:draw(w, { grid = false })
  local sr, sg, sb = at{ 0.98, 1, 0 }
  expect.gt(sr, sg + 60, "stretched: red"); expect.gt(sr, sb + 60)
  local mr, mg, mb = at{ -0.42, 1.04, 0 }
  expect.truthy(is_grey(mr, mg, mb), "away from the stretch: still grey")
  -- the colour means strain: at a strain_scale of 100 the stretch hardly shows
  r:draw(w, { grid = false, strain_scale = 100 })
  expect.truthy(is_grey(at{ 0.98, 1, 0 }), "strain_scale 100: grey")
  -- compressed by 0.1 (-40 %): a sheet's compression is its folds, shown by the
  -- shading: the colour stays grey (free links turn blue, see render_image.lua)
  shift(-0.1)
  r:draw(w, { grid = false })
  expect.truthy(is_grey(at{ 0.84, 1.04, 0 }), "compressed: grey")
  -- links off: the surface's own colour (the first surface's orange), no strain
  r:draw(w, { grid = false, constraints = false })
  local or_, og, ob = at{ 0.84, 1, 0 }
  expect.gt(or_, og + 40, "without links: orange"); expect.gt(or_, ob + 40)
end)

test("the links of a drawn surface are not drawn over it", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  standing_cloth(w, {5, 3})   -- links every 0.5
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  -- on a link (x = 0) and between links: the same colour, no line
  r:draw(w, { grid = false, line_width = 6 })
  local ar, ag, ab = at{ 0, 1.25, 0 }
  local br, bg, bb = at{ 0.25, 1.1, 0 }
  expect.lt(math.abs(ar - br) + math.abs(ag - bg) + math.abs(ab - bb), 24, "no line on the surface")
  -- without the surface the links are there
  r:draw(w, { grid = false, line_width = 6, surfaces = false, particles = false })
  local lr, lg, lb = at{ 0, 1.25, 0 }
  expect.truthy(is_grey(lr, lg, lb) and lr < 150, "a grey link")
  expect.truthy(is_sky(at{ 0.25, 1.1, 0 }), "and sky between them")
end)

test("a skin hides the cage it is bound to, unless cage = true", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local cage = standing_cloth(w, {5, 3})
  -- a free particle and a rope not bound to the skin stay visible
  local free = w:particle{ pos = {-1.4, 1, 0}, radius = 0.08 }
  local quad = wobble.mesh{ vertices = { {-0.3, 0.8, 0.05}, {0.3, 0.8, 0.05}, {0.3, 1.2, 0.05}, {-0.3, 1.2, 0.05} },
                            triangles = { {1, 2, 3}, {1, 3, 4} } }
  w:skin(quad, cage, { bones = 2, neighbours = 4 })
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  r:draw(w, { grid = false, line_width = 6 })
  local kr, _, kb = at{ 0, 1, 0.05 }
  expect.gt(kr, kb + 30, "the skin's clay colour")
  -- beyond the skin: the cage's surface and links are hidden, the sky shows
  expect.truthy(is_sky(at{ 0.75, 0.65, 0 }), "no cage surface beyond the skin")
  expect.truthy(is_sky(at{ 0.5, 1.5, 0 }), "no cage link along its top edge")
  local fr, _, fb = at{ -1.4, 1, 0.08 }
  expect.gt(fb, fr + 40, "a particle not bound to the skin is drawn")
  -- the particles of the cage too (surfaces off, so they would show as spheres)
  local cx, cy, cz = w:position(cage.particles[1])
  r:draw(w, { grid = false, surfaces = false, constraints = false })
  expect.truthy(is_sky(at{ cx, cy, cz + 0.02 }), "no cage particle")
  -- cage = true: all of it again
  r:draw(w, { grid = false, cage = true })
  expect.falsy(is_sky(at{ 0.75, 0.65, 0 }), "cage = true: its surface")
  r:draw(w, { grid = false, surfaces = false, constraints = false, cage = true })
  local pr, _, pb = at{ cx, cy, cz + 0.02 }
  expect.gt(pb, pr + 40, "cage = true: its particles")
  expect.error(function() r:draw(w, { cage = 1 }) end, "cage")
end)
