;;; examples/box-judge.scm reads the code files a lab names, by a path
;;; relative to the lab's folder or by an absolute one, and
;;; tools/box-layout.scm draws the same lab from the same seed, or refuses
;;; one with a reason.  The judge is given the simulator's last line as a
;;; run would leave it; no simulator runs here.
(import (scheme base) (scheme write) (scheme read) (scheme inexact) (scheme file) (scheme cxr) (srfi 1) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch testing harness))

(define dir (temporary-directory))

;; The judge's output and exit status for LAB, the box ending at X Y HEADING.
(define (judge lab x y heading)
  (let ((log (string-append dir "/b14.log")) (out (string-append dir "/judge.out")))
    (call-with-output-file log
      (lambda (port)
        (display (string-append "b14: box 0 ends at " (number->string x) " "
                                (number->string y) " " (number->string heading)
                                " after 61.5 s\n")
                 port)))
    (let ((status (system? "sh" "-c" "\"$0\" \"$1\" \"$2\" box-move \"$3\" >\"$4\" 2>&1"
                           (tool-path "tools/chibi") (tool-path "examples/box-judge.scm")
                           log lab out)))
      (cons status (file-text out)))))

;; Draws seed's layout into a folder of dir; (EXIT-STATUS . OUTPUT).
(define (layout seed folder)
  (let ((out (string-append dir "/layout.out")))
    (let ((status (system? "sh" "-c" "\"$0\" \"$1\" \"$2\" \"$3\" >\"$4\" 2>&1"
                           (tool-path "tools/chibi") (tool-path "tools/box-layout.scm")
                           (number->string seed) (string-append dir "/" folder) out)))
      (cons status (file-text out)))))

(test-begin "box judge and layouts")

(test-group "a lab naming its code by a path relative to its folder"
  ;; examples/box-lab.scm: (code "box-path.scm" "box-move.scm"), goal (1800 900) at 31 degrees.
  (let ((run (judge (tool-path "examples/box-lab.scm") 1750 880 29)))
    (test "a box near the goal passes" #t (car run))
    (test-assert (text-contains? (cdr run) "within 300 mm and 20 degrees")))
  (let ((run (judge (tool-path "examples/box-lab.scm") 1200 500 29)))
    (test "a box far from the goal fails" #f (car run))
    (test-assert (text-contains? (cdr run) "outside 300 mm and 20 degrees"))))

(test-group "a generated lab, naming box-move.scm by its absolute path"
  (let ((made (layout 1 "one")) (again (layout 1 "again")))
    (test "seed 1 gives a layout" #t (car made))
    (test "the same seed gives the same lab" (file-text (string-append dir "/one/lab.scm"))
      (file-text (string-append dir "/again/lab.scm")))
    (test-assert "its code names box-move.scm by an absolute path"
      (text-contains? (file-text (string-append dir "/one/lab.scm"))
                      (string-append "\"" (tool-path "examples/box-move.scm") "\"")))
    ;; Seed 1's goal: the path's last point, as path.scm says.
    (let* ((path (call-with-input-file (string-append dir "/one/path.scm") read))
           (goal (last (cadr (caddr path))))
           (legs (cadr (caddr path)))
           (from (list-ref legs (- (length legs) 2)))
           (heading (* (/ 180 (acos -1))
                       (atan (- (cadr goal) (cadr from)) (- (car goal) (car from))))))
      (let ((run (judge (string-append dir "/one/lab.scm") (car goal) (cadr goal) heading)))
        (test "the judge reads it and the box at its goal passes" #t (car run))
        (test-assert (text-contains? (cdr run) "within 300 mm and 20 degrees"))))))

;; The judge's output and exit status for a run with a fault, given a
;; trace as the simulator writes it (sim/): a box, side mm a side, heading
;; 0, moving from (0 0) to (3000 0), and one robot, kai, behind it, its
;; front 10 mm from the rear face and its centre aside mm left of the
;; face's middle; the poser's words give kai the lost pusher's part.
(define (judge-spare side aside)
  (let ((lab (string-append dir "/spare-lab.scm")) (svg (string-append dir "/trace.svg"))
        (pose-out (string-append dir "/pose.out")) (log (string-append dir "/b14.log"))
        (out (string-append dir "/judge.out")))
    (call-with-output-file lab
      (lambda (port)
        (write `(lab spare-lab (code ,(tool-path "examples/box-path.scm")
                                     ,(tool-path "examples/box-move.scm"))
                     (aspace kai (robot (pose 0 0 0)) (capabilities mobile))
                     (world (box 0 0 ,side ,side 0 5)))
               port)))
    (call-with-output-file svg
      (lambda (port)
        (display (trace-body 0 0 "<rect/>") port)
        (display (trace-body (- (+ (/ side 2) 190)) aside "<circle r=\"180\"/>") port)))
    (call-with-output-file pose-out
      (lambda (port)
        (display "pose-task: box-move@p/1: step 1 done: ((fay inside) (ada outside) lune)\n"
                 port)
        (display "pose-task:   component 2 reassigned from fay to kai\n" port)))
    (call-with-output-file log
      (lambda (port) (display "b14: box 0 ends at 1800 900 31 after 61.5 s\n" port)))
    (let ((status (system? "sh" "-c"
                           "\"$0\" \"$1\" \"$2\" box-move-fault \"$3\" \"$4\" \"$5\" >\"$6\" 2>&1"
                           (tool-path "tools/chibi") (tool-path "examples/box-judge.scm")
                           log lab svg pose-out out)))
      (cons status (file-text out)))))

;; A body's line of the trace: 101 samples 30 mm apart along x, from (dx
;; dy), heading 0.
(define (trace-body dx dy shape)
  (let ((samples (lambda (sample)
                   (let ((each (map sample (iota 101 0 30))))
                     (fold (lambda (s all) (string-append all ";" s)) (car each) (cdr each))))))
    (string-append
     "<g><animateTransform type=\"translate\" values=\""
     (samples (lambda (x) (string-append (number->string (+ x dx)) "," (number->string dy))))
     "\"/><g><animateTransform type=\"rotate\" values=\""
     (samples (lambda (x) "0.0"))
     "\"/>" shape "</g></g>\n")))

(test-group "the spare's push, from the simulator's trace"
  (let ((run (judge-spare 600 -170)))
    (test "a spare at its place behind the face pushed" #t (car run))
    (test-assert (text-contains? (cdr run) "of the last third: it pushed")))
  ;; Two bodies are wider than a 430 mm box: a spare's centre may lie past
  ;; the face's end while half its front presses the face.
  (let ((run (judge-spare 430 -255)))
    (test "a spare with its centre 40 mm past a narrow face's end pushed" #t (car run)))
  (let ((run (judge-spare 430 -340)))
    (test "a spare with a sixth of its width behind the face did not" #f (car run))
    (test-assert (text-contains? (cdr run) "it did not push to the end"))))

(test-group "a layout the team cannot do is refused, with a reason"
  ;; Seed 2's path bends 27 mm inside a wall.
  (let ((made (layout 2 "two")))
    (test "refused: exit 3" #f (car made))
    (test-assert (text-contains? (cdr made) "box-layout: seed 2: refused: "))
    (test-assert "it says what is in the way" (text-contains? (cdr made) "from a wall"))
    (test-assert "and writes no lab" (not (file-exists? (string-append dir "/two/lab.scm")))))
  ;; Seed 33's goal is 176 mm from a wall: the box arriving there would
  ;; stand in it (the goal went unchecked, and the box was pushed into the
  ;; wall and past its goal).
  (let ((made (layout 33 "thirty-three")))
    (test "refused: exit 3" #f (car made))
    (test-assert (text-contains? (cdr made) "(the goal) is 176 mm from a wall"))))

(delete-file-hierarchy dir)
(test-end)
(test-exit)
