-- api_builders.lua: w:cloth, w:rope, w:lattice: counts worked out by hand, body
-- tables, pin_where / pin_all, and builder options applied to every constraint.

local function distances(w) return w:stats().distances end

test("cloth res {3,4}: 12 particles, 17 structural + 6 shear links", function()
  -- structural: (3-1)*4 along x + 3*(4-1) along z = 8 + 9; shear: one per cell, 2*3
  local w = wobble.world{}
  local b = w:cloth{ origin = {0, 1, 0}, size = {2, 3}, res = {3, 4} }
  expect.eq(b.count, 12)
  expect.eq(#b.particles, 12)
  expect.eq(b.first, 1)
  expect.eq(distances(w), 23)
  expect.eq(b.constraint_count, 23)
  expect.eq(b.world, w)
  for i, id in ipairs(b.particles) do expect.eq(id, i) end
  -- spans +x by size[1] and +z by size[2]
  local x0, y0, z0, x1, y1, z1 = w:bounds()
  expect.near(x0, 0, 1e-12); expect.near(x1, 2, 1e-12)
  expect.near(y0, 1, 1e-12); expect.near(y1, 1, 1e-12)
  expect.near(z0, 0, 1e-12); expect.near(z1, 3, 1e-12)
  expect.truthy(tostring(b):match("^wobble%.body: .+ %(12 particles%)$"), tostring(b))
end)

test("cloth without shear, with bending", function()
  local w = wobble.world{}
  w:cloth{ res = {3, 4}, shear = false }
  expect.eq(distances(w), 17)
  -- bending links skip one particle: (3-2)*4 along x + 3*(4-2) along z = 4 + 6
  local w2 = wobble.world{}
  local b = w2:cloth{ res = {3, 4}, shear = false, bend_links = 1e-4 }
  expect.eq(b.constraint_count, 27)
  local w3 = wobble.world{}
  w3:cloth{ res = {3, 4}, bend_links = true }
  expect.eq(distances(w3), 33)
  local w4 = wobble.world{}
  w4:cloth{ res = {3, 4}, bend_links = false }
  expect.eq(distances(w4), 23)
  -- bend = dihedral bends, one per interior edge of the sheet's triangles: of the
  -- 2*4 + 3*3 + 6 = 23 edges, 2*2 + 2*3 = 10 lie on the border; no extra links
  local w5 = wobble.world{}
  w5:cloth{ res = {3, 4}, bend = 1e-4 }
  expect.eq(distances(w5), 23)
  expect.eq(#w5:bends(), 13)
  for _, bd in ipairs(w5:bends()) do expect.eq(bd:rest(), 0, "built flat") end
  local w6 = wobble.world{}
  w6:cloth{ res = {3, 4}, bend = false }
  expect.eq(#w6:bends(), 0)
end)

test("cloth mass is the total, spread evenly", function()
  local w = wobble.world{}
  local b = w:cloth{ res = {4, 5}, mass = 2 }
  local sum = 0
  for _, id in ipairs(b.particles) do sum = sum + w:mass(id) end
  expect.near(sum, 2, 1e-12)
  expect.near(w:mass(b.first), 0.1, 1e-12)
end)

test("rope: segments + 1 particles, segments links, from to to", function()
  local w = wobble.world{}
  w:particle{ pos = {9, 9, 9} }
  local b = w:rope{ from = {0, 2, 0}, to = {5, 2, 0}, segments = 5, mass = 3, radius = 0.1 }
  expect.eq(b.count, 6)
  expect.eq(b.first, 2)
  expect.eq(b.particles[1], 2); expect.eq(b.particles[6], 7)
  expect.eq(b.constraint_count, 5)
  expect.eq(distances(w), 5)
  for i, id in ipairs(b.particles) do
    local x, y, z = w:position(id)
    expect.near(x, i - 1, 1e-12); expect.eq(y, 2); expect.eq(z, 0)
    expect.near(w:mass(id), 0.5, 1e-12)
    expect.near(w:radius(id), 0.1, 1e-12)
  end
end)

test("lattice: every pair of a cell's corners is linked once", function()
  local w = wobble.world{}
  local b = w:lattice{ min = {0, 0, 0}, max = {1, 2, 3}, res = {2, 2, 2} }
  expect.eq(b.count, 8)
  expect.eq(b.constraint_count, 28) -- 8 choose 2
  local x0, y0, z0, x1, y1, z1 = w:bounds()
  expect.eq(x0, 0); expect.eq(y0, 0); expect.eq(z0, 0)
  expect.eq(x1, 1); expect.eq(y1, 2); expect.eq(z1, 3)
  -- res {3,2,2}: edges 2*2*2 + 3*1*2 + 3*2*1 = 20, face diagonals 2*(2*1*2 + 2*2*1 + 3*1*1) = 22,
  -- body diagonals 4 per cell * 2 cells = 8
  local w2 = wobble.world{}
  local b2 = w2:lattice{ res = {3, 2, 2} }
  expect.eq(b2.count, 12)
  expect.eq(b2.constraint_count, 50)
  expect.eq(w2:lattice{ res = {2, 2, 2}, tets = false }.first, 13)
end)

test("pin_where pins what the predicate selects", function()
  local w = wobble.world{}
  local b = w:cloth{ origin = {0, 1, 0}, size = {1, 1}, res = {3, 4} }
  local seen = 0
  local n = b:pin_where(function(x, y, z, id)
    seen = seen + 1
    expect.eq(math.type(id), "integer")
    return z == 0
  end)
  expect.eq(seen, 12)
  expect.eq(n, 3)
  for _, id in ipairs(b.particles) do
    local _, _, z = w:position(id)
    expect.eq(w:pinned(id), z == 0)
  end
  w:run{ frames = 20 }
  local _, y = w:position(b.particles[1])
  expect.eq(y, 1)
  local _, ylast = w:position(b.particles[12])
  expect.truthy(ylast < 1, "the free edge falls")
  expect.error(function() b:pin_where(3) end, "function expected")
  expect.error(function() b:pin_where(function() error("inner") end) end, "inner")
end)

test("pin_all and unpin_all", function()
  local w = wobble.world{}
  local b = w:rope{ segments = 3 }
  expect.eq(b:pin_all(), 4)
  for _, id in ipairs(b.particles) do expect.truthy(w:pinned(id)) end
  expect.eq(b:unpin_all(), 4)
  for _, id in ipairs(b.particles) do expect.falsy(w:pinned(id)) end
  b.particles[2] = 99
  expect.error(function() b:pin_all() end, "particle id 99 out of range")
  w:close()
  expect.error(function() b:pin_all() end, "closed world")
end)

test("builder options apply to every constraint", function()
  local function hang(opts)
    local w = wobble.world{}
    opts.from, opts.to, opts.segments = {0, 0, 0}, {1, 0, 0}, 8
    local b = w:rope(opts)
    w:pin(b.first)
    w:run{ frames = 60 }
    return w
  end
  local stiff = hang{ compliance = 0 }
  local soft = hang{ compliance = 1e-2 }
  expect.truthy(soft:max_strain() > stiff:max_strain() * 2,
                string.format("soft %g vs stiff %g", soft:max_strain(), stiff:max_strain()))
  local w = wobble.world{}
  local b = w:rope{ segments = 4, break_strain = 0.01 }
  w:pin(b.first)
  w:pin(b.particles[b.count], {3, 0, 0})
  w:step()
  expect.truthy(w:stats().broken >= 1, "stretched rope breaks")
  local c = wobble.world{}
  c:cloth{ res = {3, 3}, compliance = 1e-3, damping = 0.1, yield = 0.1, creep = 1, break_strain = 1 }
  expect.eq(distances(c), 12 + 4)
end)
