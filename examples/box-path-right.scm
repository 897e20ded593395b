;;; The path of box-lab-right.scm, as box-path.scm is box-lab.scm's: the
;;; box goes west, then bends right toward the room's north-west.
(define box-path '((2200 -1200) (500 -1200) (-800 -300)))

;; The box's side, mm.
(define box-side 600)
