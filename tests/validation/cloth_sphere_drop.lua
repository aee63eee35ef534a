-- cloth_sphere_drop.lua: the claim of scripts/cloth_sphere_drop.lua (a self-colliding cloth
-- dropped onto a sphere standing on the floor drapes over it and its skirt folds onto
-- itself without passing through), on the same scene at 48 x 48 instead of 256 x 256.
--
-- A 2 x 2 m cloth of the builder's radius (half its spacing: r = 2.1 cm here), tilted
-- 0.15 rad and 16 cm off the axis of a sphere of radius 0.3 m on the floor, falls 0.5 m
-- onto it (20 substeps, as the example). Checked from the physics, over 3 s:
--  * it drapes: the particles over the sphere's top (within 0.1 m of its axis) lie on
--    it, at R + r from its centre (a particle resting on a collider touches it with its
--    sphere); the skirt reaches the floor (a particle lying on it is at y = r);
--  * it folds: the skirt gathers into folds that lie on each other on the floor: many
--    pairs that may collide lie within 1.5 x their contact distance (a smooth sheet has
--    none: its nearest such pairs are two spacings = 2 contact distances apart), and the
--    cloth covers much less of the floor than flat;
--  * nothing passes through: every 5 frames, no two particles that may collide (all
--    pairs but those a constraint joins: links, and the four particles of a bend) are
--    closer than (r_i + r_j) (1 - tol), tol = 10% (as tests/validation/contacts.lua and
--    scripts/cloth_heap.lua): the contacts are projected once a substep, after the links,
--    which squeeze a jammed crease back by part of what the contacts pushed out (the pairs
--    in touch are swept a few times: contact.c); a fold that passed through has pairs at
--    < 1% of r_i + r_j. No particle lies below the floor or inside the sphere by more
--    than 10% of r either. The same holds for a finer cloth at fewer substeps, whose
--    creases jam harder (56 x 56, 10 substeps).
-- The twin without self-collision passes through itself (the check has power), and the
-- scene gives the same bits on one thread and on two.

local R, size, res = 0.3, 2, 48
local frames = 180

local function scene(self_collide, threads, n, substeps)
  n = n or res
  local w = wobble.world{ substeps = substeps or 20, iterations = 1, damping = 0.5, threads = threads }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.6 }
  w:collider{ shape = "sphere", center = {0, R, 0}, radius = R, friction = 0.6 }
  local cloth = w:cloth{ origin = {-size / 2, 0, -size / 2}, size = {size, size}, res = {n, n}, mass = 0.8,
                         compliance = 1e-6, bend = 1e6, self_collide = self_collide, friction = 0.5 }
  local r = w:radius(cloth.particles[1])
  -- as the example places it: tilted about x, then about y by a third of that, off the
  -- axis, its lowest point 0.5 m above the sphere's top
  local tilt, height = 0.15, 0.5
  local ct, st, cy, sy = math.cos(tilt), math.sin(tilt), math.cos(tilt / 3), math.sin(tilt / 3)
  local placed, low = {}, math.huge
  for k, p in ipairs(cloth.particles) do
    local x, _, z = w:position(p)
    local y1, z1 = z * st, z * ct
    placed[k] = { x * cy + z1 * sy + 0.07 * size, y1, -x * sy + z1 * cy + 0.04 * size }
    low = math.min(low, y1)
  end
  for k, p in ipairs(cloth.particles) do
    local q = placed[k]
    w:set_position(p, q[1], q[2] - low + 2 * R + height + r, q[3])
  end
  return w, cloth, r
end

-- pairs a constraint joins (never a contact pair): links, and each bend's four particles
local function joined_pairs(w)
  local joined = {}
  local function join(a, b) joined[math.min(a, b) * 1048576 + math.max(a, b)] = true end
  for _, c in ipairs(w:distances()) do join(c:particles()) end
  for _, b in ipairs(w:bends()) do
    local q = { b:particles() }
    for i = 1, 4 do for j = i + 1, 4 do join(q[i], q[j]) end end
  end
  return joined
end

-- the closest two particles that may collide, over r_i + r_j, and how many such pairs lie
-- within 1.5 x r_i + r_j; a spatial hash of cells 3 r wide (every pair within 1.5 x 2 r
-- lies in neighbouring cells), not all pairs
local function closest(w, cloth, r, joined)
  local cell, grid, pos = 3 * r, {}, {}
  local function key(i, j, k) return (i * 4096 + j) * 4096 + k end
  for _, p in ipairs(cloth.particles) do
    local x, y, z = w:position(p)
    pos[p] = { x, y, z }
    local kk = key(x // cell, y // cell, z // cell)
    local list = grid[kk]
    if not list then list = {}; grid[kk] = list end
    list[#list + 1] = p
  end
  local least, stacked = math.huge, 0
  for _, p in ipairs(cloth.particles) do
    local a = pos[p]
    local i, j, k = a[1] // cell, a[2] // cell, a[3] // cell
    for di = -1, 1 do for dj = -1, 1 do for dk = -1, 1 do
      local list = grid[key(i + di, j + dj, k + dk)]
      if list then
        for _, q in ipairs(list) do
          if q > p and not joined[p * 1048576 + q] then
            local b = pos[q]
            local d = math.sqrt((a[1] - b[1]) ^ 2 + (a[2] - b[2]) ^ 2 + (a[3] - b[3]) ^ 2) /
                      (w:radius(p) + w:radius(q))
            least = math.min(least, d)
            if d < 1.5 then stacked = stacked + 1 end
          end
        end
      end
    end end end
  end
  return least, stacked
end

-- how deep any particle lies in the floor or the sphere, over r
local function deepest(w, cloth, r)
  local depth = -math.huge
  for _, p in ipairs(cloth.particles) do
    local x, y, z = w:position(p)
    depth = math.max(depth, (r - y) / r, (R + r - math.sqrt(x * x + (y - R) ^ 2 + z * z)) / r)
  end
  return depth
end

-- the floor cells of the spacing under any particle: how much floor the cloth covers
local function covered(w, cloth)
  local s, n, cells = size / (res - 1), 0, {}
  for _, p in ipairs(cloth.particles) do
    local x, _, z = w:position(p)
    local k = (x // s) * 65536 + z // s
    if not cells[k] then cells[k], n = true, n + 1 end
  end
  return n
end

local function drop(self_collide, n, substeps)
  local w, cloth, r = scene(self_collide, 1, n, substeps)
  local joined = joined_pairs(w)
  local out = { least = math.huge, depth = -math.huge, flat = covered(w, cloth) }
  w:run{ frames = frames, on_frame = function(w, f)
    if f % 5 == 0 then
      local least = closest(w, cloth, r, joined)
      if least < out.least then out.least, out.at = least, f end
      out.depth = math.max(out.depth, deepest(w, cloth, r))
    end
    if f == 60 then out.hash60 = w:hash() end
  end }
  out.w, out.cloth, out.r = w, cloth, r
  out.final, out.stacked = closest(w, cloth, r, joined)
  return out
end


local with -- the self-colliding drop, run once for the tests that read it
local function dropped()
  if not with then
    with = drop(true)
    local w, cloth, r = with.w, with.cloth, with.r
    -- over the sphere's top: within 0.1 m of its axis, above its centre
    with.top_n, with.top_on, with.top_off, with.floor_n = 0, 0, 0, 0
    for _, p in ipairs(cloth.particles) do
      local x, y, z = w:position(p)
      if x * x + z * z < 0.1 ^ 2 and y > R then
        local off = math.abs(math.sqrt(x * x + (y - R) ^ 2 + z * z) - (R + r)) / r
        with.top_n, with.top_off = with.top_n + 1, math.max(with.top_off, off)
        if off < 0.05 then with.top_on = with.top_on + 1 end
      end
      if y < 1.5 * r then with.floor_n = with.floor_n + 1 end
    end
    with.covered = covered(w, cloth)
    print(string.format("%d x %d, r = %.4f m: closest non-neighbours %.3f of r_i + r_j (frame %s), deepest in a "
                        .. "collider %.3f r; at the end: %d particles over the top, %d at R + r, off by %.3f r at most, %d of "
                        .. "%d on the floor, %d pairs within 1.5 contact distances, %d floor cells covered of %d flat",
                        res, res, r, with.least, tostring(with.at), with.depth, with.top_n, with.top_on, with.top_off,
                        with.floor_n, #cloth.particles, with.stacked, with.covered, with.flat))
  end
  return with
end

test("the cloth drapes over the sphere and its skirt folds onto itself on the floor", function()
  local d = dropped()
  local n = #d.cloth.particles
  expect.gt(d.top_n, 5, "particles over the sphere's top")
  -- resting on the sphere, at R + r; a few lifted by the wrinkles, but less than a layer
  -- (a fold lying on the sheet there would put its particles 2 r higher)
  expect.gt(d.top_on, d.top_n / 2, "particles over the top at R + r from its centre (within 5% of r)")
  expect.lt(d.top_off, 1.5, "the most any particle over the top lies off R + r, over r")
  expect.gt(d.floor_n, 0.1 * n, "particles lying on the floor (y < 1.5 r)")
  -- folds lying on each other: a smooth sheet, even bent, has no such pair
  expect.gt(d.stacked, 0.2 * n, "pairs within 1.5 x their contact distance")
  expect.lt(d.covered, 0.7 * d.flat, "floor cells covered, against the flat sheet's")
end)

test("nothing passes through: no non-neighbour pair closer than 0.9 (r_i + r_j), nothing in a collider",
  function()
    local d = dropped()
    -- tol 10%: the contacts are projected after the links, and where a fold's crease
    -- jams the links squeeze it back by part of what the contacts pushed out (measured
    -- here: 4.2%, at the landing; with 10 substeps 4.8%); a fold that passed through has
    -- pairs at < 1% of r_i + r_j (the twin)
    expect.ge(d.least, 0.9, "closest non-neighbours over the run, over r_i + r_j (every 5 frames)")
    expect.lt(d.depth, 0.1, "deepest any particle lay in the floor or the sphere, over r")
  end)

-- A finer cloth (56 x 56, r = 1.8 cm) at 10 substeps jams its creases harder: projected in
-- one pass after the links, its contacts left pairs at 0.88 of r_i + r_j (0.81 at 64 x 64);
-- swept again while in touch (contact.c), 0.94. The same bound as above.
test("a finer cloth at 10 substeps: no non-neighbour pair closer than 0.9 (r_i + r_j)", function()
  local d = drop(true, 56, 10)
  print(string.format("56 x 56, 10 substeps: closest non-neighbours %.3f of r_i + r_j (frame %s), %d pairs within "
                      .. "1.5 contact distances at the end", d.least, tostring(d.at), d.stacked))
  expect.ge(d.least, 0.9, "closest non-neighbours over the run, over r_i + r_j (every 5 frames)")
  expect.lt(d.depth, 0.1, "deepest any particle lay in the floor or the sphere, over r")
  expect.gt(d.stacked, 0.2 * 56 * 56, "pairs within 1.5 x their contact distance (it folded)")
end)

test("without self-collision the same drop passes through itself (the check has power)", function()
  local d = drop(false)
  expect.lt(d.least, 0.5, "closest non-neighbours over the run, over r_i + r_j")
end)

test("the drop gives the same bits on two threads as on one", function()
  local d = dropped()
  local w = scene(true, 2)
  w:run{ frames = 60 }
  expect.gt(w:stats().particle_contacts, 0, "the cloth touches itself by frame 60")
  expect.eq(w:hash(), d.hash60, "w:hash() at frame 60")
end)
