-- restitution_threshold.lua: restitution acts only when a particle approaches faster
-- than 2|g|h (h = dt / substeps): a particle at rest on a perfectly elastic floor stays
-- at rest, while one arriving at ten times that speed rebounds at e times its speed.
-- (restitution.lua checks rebound heights from drops; this checks the threshold.)

local g, dt, substeps, r = 9.81, 1 / 60, 10, 0.05
local h = dt / substeps

local function floor_world(e)
  local w = wobble.world{ gravity = {0, -g, 0}, dt = dt, substeps = substeps }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, restitution = e }
  return w
end

test("a particle resting on a floor of restitution 1 stays at rest (no bounce below 2|g|h)", function()
  -- each substep gravity gives it g h downwards and the floor takes that back: its
  -- velocity after a substep is 0 (a bounce would give it +e g h, then gravity takes
  -- that back in the next substep: a jitter of g h). An odd substep count lets frames
  -- end on either phase of such a jitter.
  for _, n in ipairs{ 9, 10 } do
    local w = wobble.world{ gravity = {0, -g, 0}, dt = dt, substeps = n }
    w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, restitution = 1 }
    local p = w:particle{ pos = {0, r, 0}, radius = r }
    local highest, fastest = r, 0
    w:run{ seconds = 1, on_frame = function(w)
      highest = math.max(highest, select(2, w:position(p)))
      fastest = math.max(fastest, math.abs(select(2, w:velocity(p))))
    end }
    local hn = dt / n
    -- it never leaves the floor by more than a substep's fall g h^2
    expect.lt(highest - r, g * hn * hn, "it never hops, substeps " .. n)
    expect.lt(fastest, 0.01 * g * hn, "at rest at every frame's end, substeps " .. n)
  end
end)

test("a particle arriving at 10 x 2|g|h rebounds at e times its speed", function()
  local v0 = 10 * 2 * g * h -- 0.33 m/s
  for _, e in ipairs{ 1, 0.5 } do
    local w = floor_world(e)
    -- starts at the floor moving down: the contact is in the first substep, where the
    -- approach speed is v0 + g h
    local p = w:particle{ pos = {0, r, 0}, vel = {0, -v0, 0}, radius = r }
    local up
    w:run{ frames = 1 }
    local _, vy = w:velocity(p)
    -- after the bounce, the frame's remaining substeps of gravity: (substeps - 1) g h
    up = vy + (substeps - 1) * g * h
    expect.near(up, e * (v0 + g * h), 2 * g * h, "rebound speed with e = " .. e)
    expect.gt(vy, 0, "moving up after the frame, e = " .. e)
  end
end)
