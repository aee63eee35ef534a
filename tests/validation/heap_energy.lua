-- heap_energy.lua: a free body that falls into a heap on itself gains no energy.
--
-- A hand-built net (20 x 20 loose particles of 1 kg joined by rigid links, every default:
-- radius 0.02, contacts on, so it collides with itself) hung upright just above a floor
-- with friction and let go folds onto itself and the floor. Nothing outside it does work
-- but gravity, which the potential m g y counts, and the floor and its own contacts only
-- take energy out: its kinetic plus gravitational energy may never pass where it began.
-- (A new user's scene: under VBD it gained 17,000 J of its 1,980 J and flew apart, its
-- links' multipliers carried from substep to substep growing against a fold they could
-- not pull through. At 15, 25, 30 and 40 substeps it still does: docs/physics.md, "VBD".)

local g = 9.81

for _, substeps in ipairs{ 10, 20 } do
test("a hand-built net let go above the floor heaps on itself without gaining energy (" .. substeps .. " substeps)",
     function()
  local w = wobble.world{ substeps = substeps }
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0, friction = 0.5 }
  local n, s = 20, 0.05
  local ids, grid = {}, {}
  for j = 0, n - 1 do
    for i = 0, n - 1 do
      local x, y = (i - (n - 1) / 2) * s, 0.03 + j * s
      -- a ripple across the sheet so that it buckles as it lands rather than stands
      local p = w:particle{ pos = { x, y, 0.03 * math.sin(2 * math.pi * j * s / 0.3 + 2 * x) } }
      ids[#ids + 1] = p; grid[j * n + i] = p
    end
  end
  for j = 0, n - 1 do
    for i = 0, n - 1 do
      local p = grid[j * n + i]
      if i < n - 1 then w:distance(p, grid[j * n + i + 1]) end
      if j < n - 1 then w:distance(p, grid[(j + 1) * n + i]) end
      if i < n - 1 and j < n - 1 then w:distance(p, grid[(j + 1) * n + i + 1]) end
    end
  end
  local function energy()
    local e = 0
    for _, p in ipairs(ids) do
      local _, y = w:position(p)
      local vx, vy, vz = w:velocity(p)
      e = e + w:mass(p) * (g * y + 0.5 * (vx * vx + vy * vy + vz * vz))
    end
    return e
  end
  local e0 = energy()
  local emax, worst_frame, contacts = -math.huge, 0, 0
  w:run{ seconds = 4, on_frame = function(w, f)
    local e = energy()
    if e > emax then emax, worst_frame = e, f end
    contacts = math.max(contacts, w:stats().particle_contacts)
  end }
  local ke = w:energy()
  print(string.format("solver %s: energy %.2f J at the start, at most %.2f J (frame %d); kinetic %.4f J after 4 s; "
    .. "max strain %.3f; most particle contacts in a step %d", w:solver(), e0, emax, worst_frame, ke, w:max_strain(), contacts))
  -- it folded onto itself (the case is about its self-contacts)
  expect.gt(contacts, 20, "the net touches itself")
  -- 1% of the energy it starts with (its m g y above the floor, ~1,980 J) for the floor's
  -- and contacts' rounding and the solvers' first substeps
  expect.le(emax, e0 + 0.01 * e0, "its kinetic plus gravitational energy never passes the start's")
  -- and it comes to rest: its kinetic energy 1% of that after 4 s (XPBD: 0.008 J)
  expect.lt(ke, 0.01 * e0, "at rest on the floor after 4 s")
end)
end
