;;; The Tulane Mobile Robotics Laboratory of the thesis (chapter 3): two
;;; B14s with sonar, and two workstations at their safe.scm positions
;;; (one floor tile = 304.8 mm).  moseley starts closest to the dual-sonar
;;; task's first target, ernst closest to its second; praline has the
;;; lowest load.

(lab tulane
  (port-base 7100)
  (key-file "tulane.key")
  (code "dual-sonar.scm")
  (aspace moseley
    (robot (pose 1200 -400 180) (tethered #f) (battery 13.6))
    (capabilities sonar ir bumpers speech buttons lights mobile))
  (aspace ernst
    (robot (pose -1800 -600 90) (tethered #f) (battery 13.4))
    (capabilities sonar ir bumpers speech buttons lights mobile))
  (aspace troy
    (position -1524 -2743.2 90)
    (capabilities camera)
    (load 0.5))
  (aspace praline
    (position -2438.4 3048 -90)
    (load 0.1))
  (world
    (wall -4000 -4000  4000 -4000)
    (wall  4000 -4000  4000  4000)
    (wall  4000  4000 -4000  4000)
    (wall -4000  4000 -4000 -4000)
    (box 1800 1800 600 600 0)))
