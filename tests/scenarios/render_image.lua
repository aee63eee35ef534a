-- render_image.lua: the renderer's pictures, checked pixel by pixel. Small frames
-- (160x120) keep it fast; known world points are projected with r:project and the
-- colours found there compared with what the layer draws, with tolerances wide
-- enough for lighting and anti-aliasing but not for a missing or misplaced layer.

local W, H = 160, 120
local r = wobble.renderer{ width = W, height = H, samples = 4 }   -- one context for the file

local function rgb(x, y) return r:pixel(x, y) end

-- the pixel where world point p lands (must be inside the frame)
local function at(p)
  local x, y = r:project(p[1], p[2], p[3])
  expect.truthy(x, "point in front of the camera")
  expect.truthy(x >= 0 and x < W and y >= 0 and y < H, "point inside the frame")
  return rgb(x, y)
end

local function is_grey(cr, cg, cb, lo, hi)
  return math.abs(cr - cg) < 22 and math.abs(cg - cb) < 28 and cr >= lo and cr <= hi
end

test("size, row order and the sky", function()
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  w:particle{ pos = {0, 1, 0} }
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  r:draw(w, { particles = false })
  local iw, ih = r:size()
  expect.eq(iw, W); expect.eq(ih, H)
  expect.eq(#r:image(), W * H * 3)
  -- top: sky, bluer than red; bottom: the ground, grey
  local tr, tg, tb = rgb(W / 2, 0)
  expect.gt(tb, tr + 30, "the top row is sky (first row of the image is the top)")
  local br, bg, bb = rgb(W / 2, H - 1)
  expect.truthy(is_grey(br, bg, bb, 120, 250), "the bottom row is the lit ground")
  expect.lt(tb - tr, 90)
end)

test("a sphere collider appears where the camera sees its centre, and only with colliders on", function()
  local w = wobble.world{}
  w:collider{ shape = "sphere", center = {0.5, 1, 0}, radius = 0.4 }
  r:camera{ eye = {0, 1.2, 5}, target = {0, 1, 0}, fov = 40 }
  r:draw(w, { grid = false })
  local cr, cg, cb = at{ 0.5, 1, 0.4 }   -- the front of the sphere
  expect.truthy(is_grey(cr, cg, cb, 70, 230), "the sphere's shaded grey")
  -- left of the sphere: sky
  local sr, sg, sb = at{ -1.0, 1.9, 0 }
  expect.gt(sb, sr + 20)
  r:draw(w, { grid = false, colliders = false })
  local nr, ng, nb = at{ 0.5, 1, 0.4 }
  expect.gt(math.abs(nr - cr) + math.abs(ng - cg) + math.abs(nb - cb), 60, "without colliders the sky shows there")
end)

-- the colour at world point p with and without colliders: a collider is there when the
-- two differ (the sky and the ground are the same in both) and it is grey
local function collider_at(w, p)
  r:draw(w, { grid = false })
  local cr, cg, cb = at(p)
  r:draw(w, { grid = false, colliders = false })
  local nr, ng, nb = at(p)
  local diff = math.abs(cr - nr) + math.abs(cg - ng) + math.abs(cb - nb)
  return diff > 30 and is_grey(cr, cg, cb, 40, 235), diff
end

test("box and capsule colliders are drawn at their poses, rotations included", function()
  local w = wobble.world{}
  local c, s = math.cos(math.pi / 8), math.sin(math.pi / 8)   -- 45 degrees about z
  -- a box turned 45 degrees about z (a diamond seen from the front), an upright capsule,
  -- and a capsule lying along x
  local box = w:collider{ shape = "box", center = {-1, 1, 0}, half = {0.3, 0.3, 0.3}, rotation = {c, 0, 0, s} }
  w:collider{ shape = "capsule", a = {0.8, 0.6, 0}, b = {0.8, 1.4, 0}, radius = 0.15 }
  w:collider{ shape = "capsule", a = {-0.6, 0.2, 0}, b = {0.4, 0.2, 0}, radius = 0.1 }
  r:camera{ eye = {0, 1, 5}, target = {0, 1, 0} }
  local inside = {
    { -1, 1, 0.3, "the box's centre" }, { -0.62, 1, 0.3, "the box's right corner, beyond an unturned box" },
    { -1, 1.38, 0.3, "the box's top corner" },
    { 0.8, 1.0, 0.15, "the upright capsule's middle" }, { 0.8, 1.48, 0.1, "its upper cap" },
    { 0.8, 0.5, 0.08, "its lower cap" }, { -0.1, 0.2, 0.1, "the lying capsule's middle" },
    { 0.47, 0.2, 0.05, "its end cap" },
  }
  for _, p in ipairs(inside) do
    local yes, diff = collider_at(w, p)
    expect.truthy(yes, p[4] .. " is drawn (difference " .. diff .. ")")
  end
  local outside = {
    { -0.73, 1.27, 0.3, "the corner an unturned box would have" }, { 1.05, 1.0, 0, "right of the capsule" },
    { 0.8, 1.65, 0, "above its cap" }, { -0.1, 0.4, 0, "above the lying capsule" },
  }
  for _, p in ipairs(outside) do
    local yes, diff = collider_at(w, p)
    expect.falsy(yes, p[4] .. " is empty (difference " .. diff .. ")")
  end
  -- move the box: it is drawn at its new place after a step, and gone from the old one
  box:set_position(0, 1, 0)
  w:step()
  expect.truthy(collider_at(w, { 0, 1, 0.3 }), "the box moved")
  expect.falsy(collider_at(w, { -1, 1, 0.3 }), "and left its old place")
end)

test("the key light shades solids and casts their shadows on the ground", function()
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  w:collider{ shape = "sphere", center = {0, 1, 0}, radius = 0.4 }
  r:camera{ eye = {1, 3, 4}, target = {0.2, 0.4, 0} }
  r:draw(w)
  local function brightness(p)
    local cr, cg, cb = at(p)
    return cr + cg + cb
  end
  -- the light comes from (-0.4, 0.8, 0.45): the sphere's side towards it is bright,
  -- the side away from it has the ambient light only
  local function on_sphere(nx, ny, nz)
    local l = math.sqrt(nx * nx + ny * ny + nz * nz)
    return { 0.4 * nx / l, 1 + 0.4 * ny / l, 0.4 * nz / l }
  end
  local lit, dark = brightness(on_sphere(-0.4, 0.8, 0.45)), brightness(on_sphere(0.6, -0.5, 0.6))
  expect.gt(lit, dark + 150, "the lit side is brighter than the side away from the light")
  -- the shadow: the ground where the light's ray through the centre lands is darker
  -- with the sphere than without it
  local shadow = { 0.4 / 0.8, 0, -0.45 / 0.8 }
  local with = brightness(shadow)
  r:draw(w, { colliders = false })
  local without = brightness(shadow)
  expect.lt(with, without - 90, "the sphere's shadow on the ground")
end)

test("a cloth is a shaded two-sided surface where its particles are", function()
  local w = wobble.world{}
  local cloth = w:cloth{ origin = {-1, 0.5, 0}, size = {2, 1}, res = {8, 5} }
  -- stand it up: rotate the flat sheet into the xy plane facing the camera
  for _, id in ipairs(cloth.particles) do
    local x, _, z = w:position(id)
    w:set_position(id, x, 0.5 + z, 0)
  end
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  r:draw(w, { constraints = false, grid = false })
  local cr, cg, cb = at{ 0, 1, 0 }
  expect.gt(cr, cg + 40, "the cloth's orange"); expect.gt(cr, cb + 40)
  -- from behind: still drawn (two-sided), darker
  r:camera{ eye = {0, 1, -4}, target = {0, 1, 0} }
  r:draw(w, { constraints = false, grid = false })
  local br, bg, bb = at{ 0, 1, 0 }
  expect.gt(br, bg + 25, "the back side is drawn too"); expect.gt(br, bb + 25)
  -- no surfaces, no particles, no links: the sky
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  r:draw(w, { constraints = false, grid = false, surfaces = false, particles = false })
  local sr, _, sb = at{ 0.06, 1.06, 0 }
  expect.gt(sb, sr + 20)
  -- with surfaces off, the particles show as blue spheres
  r:draw(w, { constraints = false, grid = false, surfaces = false })
  local x, y, z = w:position(cloth.particles[20])
  local pr, _, pb = at{ x, y, z }
  expect.gt(pb, pr + 40, "a particle sphere")
end)

test("links are grey at rest, red stretched, blue compressed", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local a = w:particle{ pos = {-1, 1.5, 0}, radius = 0.01 }
  local b = w:particle{ pos = {1, 1.5, 0}, radius = 0.01 }
  local c = w:particle{ pos = {-1, 1, 0}, radius = 0.01 }
  local d = w:particle{ pos = {1, 1, 0}, radius = 0.01 }
  local e = w:particle{ pos = {-1, 0.5, 0}, radius = 0.01 }
  local f = w:particle{ pos = {1, 0.5, 0}, radius = 0.01 }
  w:distance(a, b)                 -- at rest
  w:distance(c, d, { rest = 1.0 })  -- length 2: strain +1
  w:distance(e, f, { rest = 4.0 })  -- length 2: strain -0.5
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  r:draw(w, { grid = false, particles = false, line_width = 8 })
  local gr, gg, gb = at{ 0.5, 1.5, 0 }
  expect.truthy(is_grey(gr, gg, gb, 60, 170), "rest: grey")
  local rr, rg, rb = at{ 0.5, 1, 0 }
  expect.gt(rr, 180, "stretched: red"); expect.lt(rg, 90); expect.lt(rb, 90)
  local br, _, bb = at{ 0.5, 0.5, 0 }
  expect.gt(bb, br + 80, "compressed: blue")
  -- strain_scale decides how red: 100 times larger, the stretched link is nearly grey
  r:draw(w, { grid = false, particles = false, line_width = 8, strain_scale = 100 })
  local sr, sg, sb = at{ 0.5, 1, 0 }
  expect.truthy(is_grey(sr, sg, sb, 60, 170), "at a large strain_scale the stretch hardly shows")
end)

test("pinned particles are marked", function()
  local w = wobble.world{}
  local p = w:particle{ pos = {0, 1, 0}, radius = 0.05 }
  local q = w:particle{ pos = {0.6, 1, 0}, radius = 0.05 }
  w:pin(p)
  r:camera{ eye = {0, 1, 3}, target = {0.3, 1, 0} }
  r:draw(w, { grid = false })
  local pr, pg, pb = at{ 0, 1, 0.06 }
  expect.gt(pr, 170, "pin: amber"); expect.gt(pg, 100); expect.lt(pb, 90)
  local qr, _, qb = at{ 0.6, 1, 0.05 }
  expect.gt(qb, qr + 40, "a free particle: blue")
  r:draw(w, { grid = false, pins = false, particles = false })
  local nr, _, nb = at{ 0, 1, 0.06 }
  expect.gt(nb, nr + 20, "pins = false: no mark")
end)

test("the default camera frames the world", function()
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  local ids = {}
  for i = 0, 4 do ids[#ids + 1] = w:particle{ pos = {10 + i, 3 + i % 2, -5 - i} } end
  r:camera()   -- back to the default
  r:draw(w)
  for _, id in ipairs(ids) do
    local x, y = r:project(w:position(id))
    expect.truthy(x and x > 0 and x < W and y > 0 and y < H, "particle " .. id .. " in the frame")
  end
  local cam = r:get_camera()
  expect.eq(#cam.eye, 3); expect.gt(cam.fov, 0)
end)

test("the null backend draws nothing but keeps the camera", function()
  local n = wobble.renderer{ width = 64, height = 48, backend = "null" }
  local w = wobble.world{}
  w:particle{ pos = {0, 0, 0} }
  n:draw(w)
  local x, y = n:project(0, 0, 0)
  expect.near(x, 32, 1); expect.near(y, 24, 1)
  local tr, _, tb = n:pixel(0, 0)
  expect.gt(tb, tr, "the sky's colour")
  expect.eq(select(2, n:info()), 1)
  n:close()
end)

test("skins are drawn as smooth-shaded meshes and follow their particles", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local ids = {}
  for _, p in ipairs{ {-0.5, 0.5, 0}, {0.5, 0.5, 0}, {0.5, 1.5, 0}, {-0.5, 1.5, 0} } do
    ids[#ids + 1] = w:particle{ pos = p, radius = 0.01 }
  end
  local quad = wobble.mesh{ vertices = { {-0.5, 0.5, 0}, {0.5, 0.5, 0}, {0.5, 1.5, 0}, {-0.5, 1.5, 0} },
                            triangles = { {1, 2, 3}, {1, 3, 4} } }
  w:skin(quad, ids, { bones = 1, neighbours = 3 })
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  r:draw(w, { grid = false })
  local cr, cg, cb = at{ 0, 1, 0 }
  expect.gt(cr, cb + 30, "the skin's clay colour"); expect.gt(cr, 120)
  r:draw(w, { grid = false, skins = false })
  local sr, _, sb = at{ 0, 1, 0 }
  expect.gt(sb, sr + 20, "skins = false: the sky")
  -- move every particle by +1.2 in x: the skin goes with them
  for _, id in ipairs(ids) do
    local x, y, z = w:position(id)
    w:set_position(id, x + 1.2, y, z)
  end
  r:draw(w, { grid = false })
  local mr, _, mb = at{ 1.2, 1, 0 }
  expect.gt(mr, mb + 30, "the skin moved with its particles")
  local or_, _, ob = at{ 0, 1, 0 }
  expect.gt(ob, or_ + 20, "and left the sky behind")
end)
