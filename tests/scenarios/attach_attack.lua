-- attach_attack.lua: what the attack on attachments and grabs found: the hash
-- of a world whose attachment lost its collider equals its snapshot's; thousands of
-- attachments and grabs are made and listed in linear time, dead slots reused lowest
-- first.

test("the hash drops an attachment whose collider was removed, as a snapshot does", function()
  local w = wobble.world{}
  local c = w:collider{ shape = "sphere", center = {0, 0, 0}, radius = 0.1 }
  local keep = w:collider{ shape = "sphere", center = {3, 0, 0}, radius = 0.1 }
  local p = w:particle{ pos = {0, 1, 0} }
  local q = w:particle{ pos = {3, 1, 0} }
  w:attach(q, keep)
  local a = w:attach(p, c)
  c:remove()                      -- not stepped: the slot is still there, inert
  expect.eq(a:valid(), false)
  expect.eq(w:save("attach_attack/gone.json"), true)
  local v = assert(wobble.load("attach_attack/gone.json"))
  expect.eq(v:stats().attachments, 1)
  expect.eq(v:hash(), w:hash(), "the same state, the same hash")
  w:step() v:step()
  expect.eq(v:hash(), w:hash())
end)

-- 200000 of each: a scan for the lowest dead slot per new one, or wb_attach_at per
-- listed one, made this about a minute (quadratic); linear it is a fraction of a second.
-- The budget is generous (machines shared by several jobs).
test("200000 attachments and grabs made, churned and listed in linear time", function()
  local w = wobble.world{}
  local c = w:collider{ shape = "sphere", center = {0, 0, 0}, radius = 0.1 }
  local N = 200000
  for i = 1, N do w:particle{ pos = {(i % 400) * 0.1, 1 + (i // 400) * 0.1, 0} } end
  local t = os.clock()
  local as, gs = {}, {}
  for i = 1, N do as[i] = w:attach(i, c) end
  for i = 1, N do gs[i] = w:grab(i, {0, 0, 0}) end
  -- churn: free the upper half then refill it (each search starts at the lowest hole)
  for i = N // 2, N do as[i]:remove() gs[i]:release() end
  for i = N // 2, N do as[i] = w:attach(i, c) gs[i] = w:grab(i, {0, 0, 0}) end
  local la, lg = w:attachments(), w:grabs()
  local dt = os.clock() - t
  expect.eq(#la, N)
  expect.eq(#lg, N)
  expect.eq(la[N] == as[N], true, "listed in slot order")
  expect.eq(lg[N // 2] == gs[N // 2], true)
  expect.lt(dt, 10, "linear, not quadratic")
end)

test("a freed slot is reused lowest first, old handles of it stay stale", function()
  local w = wobble.world{}
  local c = w:collider{ shape = "sphere", center = {0, 0, 0}, radius = 0.1 }
  for i = 1, 4 do w:particle{ pos = {i, 1, 0} } end
  local a = {}
  for i = 1, 4 do a[i] = w:attach(i, c) end
  a[3]:remove()
  a[2]:remove()
  local n2 = w:attach(4, c)       -- takes slot 2, the lowest hole
  local n3 = w:attach(1, c)       -- then slot 3
  local n5 = w:attach(2, c)       -- then a new one
  local l = w:attachments()
  expect.eq(#l, 5)
  expect.eq(l[2] == n2 and l[3] == n3 and l[5] == n5, true)
  expect.eq(a[2]:valid() or a[3]:valid(), false)
  expect.eq(l[2]:particle(), 4)
  local g = {}
  for i = 1, 3 do g[i] = w:grab(i, {0, 0, 0}) end
  g[1]:release()
  local h = w:grab(4, {1, 1, 1})
  expect.eq(w:grabs()[1] == h, true)
  expect.eq(g[1]:valid(), false)
end)
