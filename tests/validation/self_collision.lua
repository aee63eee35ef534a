-- self_collision.lua: a fine cloth (radius half its spacing, the builders' default) folded
-- onto itself by a script never passes through itself. Its triangles are covered by its
-- particles' spheres, so its self-collision is the particle pairs' alone (broadphase.c,
-- "Self-collision by particles where they cover the surface"): a particle of one layer
-- cannot slip between two of the other's without touching them.
--
-- A 1 m cloth of 25 x 25 lies on the floor; its edge at x = 1 is grabbed and carried over
-- in a half circle of radius 0.25 m onto the other half, then let go. Two layers must
-- result: every particle of the folded part that lies over the other part rests on it:
-- the floor holds the lower layer at y = r, and a sphere of the upper layer sits at most
-- as deep as the hollow of four touching lower ones, sqrt(2) r above their centres, so at
-- y >= (1 + sqrt 2) r; a fold that passed through would lie at r or below. And no
-- pair but rest neighbours overlaps by more than 5% of 2 r (the links pull back after
-- the contact pass). Without self-collision the same fold interpenetrates: the twin.

local function fold(self_collide)
  local w = wobble.world{ damping = 1 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
  local n = 25
  local c = w:cloth{ origin = {0, 0, 0}, size = {1, 1}, res = {n, n}, mass = 0.5, self_collide = self_collide,
                     friction = 0.5 }
  local r = w:radius(c.particles[1])
  for _, p in ipairs(c.particles) do
    local x, _, z = w:position(p)
    w:set_position(p, x, r, z) -- resting on the floor
  end
  -- the edge x = 1, grabbed where it is
  local grabs, edge = {}, {}
  for _, p in ipairs(c.particles) do
    local x, y, z = w:position(p)
    if x > 1 - 1e-9 then
      grabs[#grabs + 1] = { g = w:grab(p, {x, y, z}), z = z }
      edge[#edge + 1] = p
    end
  end
  -- carried over the fold line x = 0.5 on a half circle of radius 0.25 about (0.75 -> 0.25)
  local frames = 120
  w:run{ frames = frames, on_frame = function(w, f)
    local a = math.pi * math.min(f / frames, 1)
    for _, e in ipairs(grabs) do
      e.g:move(0.5 + 0.5 * math.cos(a) * 0.5 + 0.25 * math.cos(a), r + 0.25 * math.sin(a) + 4 * r * math.sin(a / 2) ^ 2,
               e.z)
    end
  end }
  for _, e in ipairs(grabs) do e.g:release() end
  w:run{ seconds = 2 }
  return w, c, r
end

local function layers(w, c, r)
  -- the folded part: particles whose built x was > 0.55 (built: the cloth's order); how
  -- many of those now lie over the lower part (x < 0.45) and how low the lowest is
  local low, over = math.huge, 0
  for k, p in ipairs(c.particles) do
    local bx = ((k - 1) % 25) / 24
    local x, y = w:position(p)
    if bx > 0.55 and x < 0.45 then
      over = over + 1
      low = math.min(low, y)
    end
  end
  return over, low
end

test("a fine cloth folded over onto itself by a script lies in two layers", function()
  local w, c, r = fold(true)
  local over, low = layers(w, c, r)
  expect.gt(over, 100, "folded particles lying over the other half")
  -- (1 + sqrt 2) r, less the links' pull after the contact pass (5% of 2 r)
  expect.gt(low, (1 + math.sqrt(2)) * r - 0.1 * r, "the lowest folded particle rests on the lower layer")
  -- no pair overlapping by more than 5% of 2 r, but rest neighbours (within 2 r when built)
  local ps, worst = c.particles, 0
  local built = {}
  for k, p in ipairs(ps) do built[p] = { ((k - 1) % 25) / 24, ((k - 1) // 25) / 24 } end
  for i = 1, #ps do
    local xi, yi, zi = w:position(ps[i])
    for j = i + 1, #ps do
      local bi, bj = built[ps[i]], built[ps[j]]
      if (bi[1] - bj[1]) ^ 2 + (bi[2] - bj[2]) ^ 2 > (2 * r) ^ 2 * 1.0001 then
        local xj, yj, zj = w:position(ps[j])
        local d = math.sqrt((xi - xj) ^ 2 + (yi - yj) ^ 2 + (zi - zj) ^ 2)
        worst = math.max(worst, (2 * r - d) / (2 * r))
      end
    end
  end
  expect.lt(worst, 0.05, "deepest overlap of a non-neighbour pair, share of 2 r")
end)

test("without self-collision the same fold passes into the lower layer (the test has power)", function()
  local w, c, r = fold(false)
  local over, low = layers(w, c, r)
  expect.gt(over, 100, "folded particles lying over the other half")
  expect.lt(low, 2 * r, "the folded part sank into the lower layer")
end)

-- A 32 x 32 cloth (1.5 m, friction 0.8) stood up on its edge and let fall into a heap of
-- folds on itself comes to rest: its centre falls about 0.75 m, so it lands at up to
-- sqrt(2 g 0.75) = 3.8 m/s, and a heap held by friction then stands still. What the
-- solver leaves over the last two of six seconds is bounded at 1.5% of that landing speed,
-- 0.057 m/s rms. The particle pairs' static friction once took its budget from every
-- correction, the repair of overlap the links keep pressing shut included: that friction
-- pushed the heap about, and it kept moving at 0.30 m/s rms (contact.c's friction pass
-- now takes it from the corrections that hold the pair apart, as the dynamic friction
-- does: 0.020 m/s).
-- the heap of an n x n cloth: its rms speed over the last 2 of 6 s and its highest particle
local function heap(n)
  local w = wobble.world{ damping = 0.5 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.8 }
  local c = w:cloth{ origin = {-0.75, 0, 0}, size = {1.5, 1.5}, res = {n, n}, mass = 1, self_collide = true,
                     friction = 0.8, compliance = 1e-6 }
  local r = w:radius(c.particles[1])
  for _, p in ipairs(c.particles) do -- stood up in x-y, rippled, its lower edge 2 r up
    local x, _, z = w:position(p)
    w:set_position(p, x, z + 2 * r, 0.02 * math.sin(20 * z + 2 * x))
    w:set_velocity(p, -0.3 * x * z, 0, 0.2 * math.sin(9 * z + 1.5 * x))
  end
  local sum, k, top = 0, 0, 0
  for f = 1, 360 do
    w:step()
    if f > 240 then
      local ke = 0
      for _, p in ipairs(c.particles) do
        local vx, vy, vz = w:velocity(p)
        ke = ke + vx * vx + vy * vy + vz * vz
      end
      sum, k = sum + ke / #c.particles, k + 1
    end
  end
  for _, p in ipairs(c.particles) do top = math.max(top, select(2, w:position(p))) end
  return math.sqrt(sum / k), top
end

test("a cloth fallen into a heap on itself comes to rest", function()
  local rms, top = heap(32)
  expect.lt(top, 0.5, "it fell into a heap (its highest particle, m)")
  expect.lt(rms, 0.057, "rms speed over the last 2 s (m/s)")
end)

-- The same heap of a 64 x 64 cloth, whose folds jam harder. Its contacts projected in one
-- pass left its pairs overlapping, and the static friction, bounded by corrections that
-- were the repair of folds the links keep pressing shut, stirred it in bursts: 0.045 m/s
-- rms over the last 2 s (0.009-0.12 over eight variants of its initial swirl), single
-- particles at 3 m/s; without friction 0.006. With the pairs in touch swept again
-- (contact.c): 0.020 (0.005-0.020). Bounded at 0.8% of the landing speed, 0.03 m/s.
test("a 64 x 64 cloth fallen into a heap on itself comes to rest", function()
  local rms, top = heap(64)
  print(string.format("64 x 64 heap: rms speed over the last 2 s %.4f m/s, highest particle %.3f m", rms, top))
  expect.lt(top, 0.5, "it fell into a heap (its highest particle, m)")
  expect.lt(rms, 0.03, "rms speed over the last 2 s (m/s)")
end)

test("a self-colliding cloth bunched in its plane touches nothing: the same as without", function()
  -- A w:cloth of radius half its spacing, squeezed to 70% in its plane (no gravity): the
  -- corners across each square's unlinked diagonal come to 0.7 x 2.83 r = 1.98 r, within
  -- r_i + r_j. They are rest neighbours along the cloth (made within pi / 2 (r_i + r_j),
  -- 4 r along two links), which only shearing or bunching brings together, never a fold,
  -- so the cloth moves exactly as without self-collision. Soft links (compliance 0.1) let
  -- it spread back slowly: stiff ones throw it past its size and it bunches up elsewhere,
  -- and after 9 frames the soft one buckles out of its plane into folds that do touch.
  local n = 12
  local function squeezed(self_collide)
    local w = wobble.world{ gravity = {0, 0, 0} }
    local c = w:cloth{ origin = {0, 1, 0}, size = {0.2, 0.2}, res = {n, n}, mass = 0.1, self_collide = self_collide,
                       compliance = 0.1 }
    for _, p in ipairs(c.particles) do
      local x, y, z = w:position(p)
      w:set_position(p, 0.7 * x, y, 0.7 * z)
    end
    return w, c
  end
  local a, ca = squeezed(true)
  local b, cb = squeezed(false)
  local r, s = a:radius(ca.particles[1]), 0.2 / (n - 1)
  expect.near(r, s / 2, 1e-12, "the builder's radius: half the spacing")
  local contacts = 0
  for _ = 1, 8 do
    a:step()
    b:step()
    contacts = contacts + a:stats().particle_contacts
  end
  expect.eq(contacts, 0, "no contact in the bunched cloth")
  local worst = 0
  for k, p in ipairs(ca.particles) do
    local x1, y1, z1 = a:position(p)
    local x2, y2, z2 = b:position(cb.particles[k])
    worst = math.max(worst, math.abs(x1 - x2), math.abs(y1 - y2), math.abs(z1 - z2))
  end
  expect.eq(worst, 0, "the same positions as without self-collision, bit for bit")
end)
