-- rigid_particle_rebound.lua: a rigid box dropped on particles that cannot move (a pinned
-- lattice) rebounds at its restitution, and not at all with restitution 0. Immovable
-- particles store no energy, so whatever comes back is the contact's: the normal relative
-- velocity after a contact is -e times the one it came in with (Müller et al. 2020 eq. 34).
--
-- The box's contacts are solved together (rigid_particle.c): with one pass per substep
-- that saw the body N times heavier for N contacts, the box came out of the bed by less
-- than its overlap (an edge particle's share also turned it), kept the rest to the next
-- substep and was pushed out of it there in full: it rebounded at 12% of its impact speed
-- with restitution 0, and at 9% and 8% with restitution 0.5 and 0.8 (restitution was lost
-- in the pushes).
--
-- Speeds are read at frame ends: the impact speed read a frame before the box lands is
-- short of the true one by at most g dt, and the rebound read a frame after it leaves is
-- short by at most g dt, so rebound / impact is within (1 + e) g dt / v of e.

local g, dt = 9.81, 1 / 60

local function drop(opts)
  local w = wobble.world{ substeps = 10, threads = opts.threads }
  local S = 0.5
  local bed = w:lattice{ min = {-S / 2, 0.05, -S / 2}, max = {S / 2, 0.05 + S / 2, S / 2}, res = {6, 4, 6}, mass = 4 }
  bed:pin_all()
  local th = math.rad(opts.tilt or 0)
  local box = w:rigid{ shape = "box", half = {0.15, 0.05, 0.15}, mass = 20, pos = {0, 0.05 + S / 2 + 0.6, 0},
                       rotation = {math.cos(th / 2), 0, 0, math.sin(th / 2)}, friction = 0.5,
                       restitution = opts.e or 0 }
  local k, p = w:energy()
  local e0, emax, vin, vout = k + p, -math.huge, 0, -math.huge
  w:run{ seconds = 1.2, on_frame = function(w)
    local k, p = w:energy()
    emax = math.max(emax, k + p)
    local _, vy = box:velocity()
    vin = math.min(vin, vy)
    if vin < -1 then vout = math.max(vout, vy) end
  end }
  return { impact = -vin, rebound = vout / -vin, e0 = e0, emax = emax, hash = w:hash() }
end

test("a box dropped flat on immovable particles with restitution 0 does not rebound", function()
  local r = drop{}
  expect.gt(r.impact, 3, "it fell 0.6 m")
  expect.lt(r.rebound, 0.01, "rebound / impact (measured 0; 0.12 with the contacts pushed out one by one)")
  expect.le(r.emax, r.e0 + 1e-6, "the energy never exceeds the drop's")
end)

test("on immovable particles a box rebounds at its restitution", function()
  for _, e in ipairs{ 0.5, 0.8 } do
    local r = drop{ e = e }
    expect.near(r.rebound, e, (1 + e) * g * dt / r.impact, "rebound / impact, e = " .. e)
    expect.le(r.emax, r.e0 + 1e-6, "the energy never exceeds the drop's, e = " .. e)
  end
end)

test("a box dropped tilted 15 degrees on immovable particles lands on an edge and stays", function()
  -- the edge lands first and the box slaps flat: with restitution 0 neither comes back
  -- (measured 0.016; 0.086 with the contacts pushed out one by one)
  local r = drop{ tilt = 15 }
  expect.lt(r.rebound, 0.05, "rebound / impact")
  expect.le(r.emax, r.e0 + 1e-6, "the energy never exceeds the drop's")
end)

test("the joint solve gives the same world for any thread count", function()
  expect.eq(drop{ e = 0.5, threads = 1 }.hash, drop{ e = 0.5, threads = 2 }.hash, "hash")
end)
