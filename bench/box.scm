;;; make bench-box: the box team (examples/box-move.scm) on layouts it has
;;; never seen, drawn by tools/box-layout.scm from seeds BOX_SEED (default
;;; 1) on: BOX_RUNS (default 20) without a fault and BOX_FAULT_RUNS (default
;;; 10) with one, the pusher and the time the layout's seed draws, two
;;; without a fault to one with, each layout once.  Each run is `make
;;; demo-box`'s, judged by examples/box-judge.scm: a success is the box
;;; within 300 mm and 20 degrees of its goal, and with a fault the spare at
;;; its rear face for nine tenths of the last third of its travel.  The runs
;;; steer in real time, one at a time: about a minute each.
;;;
;;; Prints a line a run, each failure with its seed and the task's own
;;; words, the layouts refused and why, then
;;;   bench: box-success-rate P %          (target 95)
;;;   bench: box-fault-success-rate P %    (target 90)
;;;   bench: box-goal-error-p50 MM mm, box-goal-error-p95 MM mm
;;;   bench: box-sim-seconds-p50 S s, box-wall-seconds-p50 S s (and -p95)
(import (scheme base) (scheme write) (scheme read) (scheme cxr) (scheme inexact)
        (scheme time) (scheme process-context) (srfi 1) (srfi 132) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy)
        (only (chibi string) string-split)
        (murdoch testing harness))
(include "tests/box-move-cases.scm")

(define (setting name default)
  (let ((v (get-environment-variable name)))
    (or (and v (string->number v)) default)))

(define (say . parts) (for-each display parts) (newline) (flush-output-port))

;; One run: (SEED FAULT? SUCCESS? GOAL-MM SIM-S WALL-S WORDS).
(define (run-layout seed dir words fault?)
  (let* ((fault (layout-fault words))
         (start (current-second))
         (run (if fault?
                  (run-demo (string-append dir "/lab.scm") (car fault) (cadr fault))
                  (run-demo (string-append dir "/lab.scm") "")))
         (wall (- (current-second) start))
         (text (cdr run))
         (mm (bench text (if fault? "box-move-fault-goal-error-mm" "box-move-goal-error-mm")))
         (ok? (and (text-contains? text "within 300 mm and 20 degrees")
                   (or (not fault?) (text-contains? text ": it pushed")))))
    (list seed fault? ok? mm (bench text "box-move-sim-seconds") wall
          (task-words text))))

;; What the task and the judge said of a run that went wrong: the lines
;; that name an error or a failure, and the judge's verdicts.
(define (task-words text)
  (filter (lambda (line)
            (or (text-contains? line "error") (text-contains? line "failed")
                (text-contains? line "box-move: ") (text-contains? line "FAULT")
                (text-contains? line "did not")))
          (text-lines text)))

(define (cut-line s) (if (> (string-length s) 400) (string-append (substring s 0 400) "...") s))

(define (report r)
  (let-values (((seed fault? ok? mm sim wall words) (apply values r)))
    (say "box-bench: seed " seed (if fault? ", a pusher killed" "") ": "
         (if ok? "arrived" "FAILED") ", " (or mm "no") " mm off, " (or sim "?")
         " s simulated, " (exact (round wall)) " s wall")
    (if (not ok?)
        (for-each (lambda (line) (say "    " (cut-line line))) words))))

(define (percentile xs p)
  (if (null? xs)
      "-"
      (let ((v (list->vector (list-sort < xs))))
        (vector-ref v (min (- (vector-length v) 1)
                           (exact (floor (* p (vector-length v)))))))))

(define (rate rs)
  (if (null? rs)
      "-"
      (/ (round (* 1000 (/ (count (lambda (r) (list-ref r 2)) rs) (length rs)))) 10.)))

(define (main)
  (let ((plain (setting "BOX_RUNS" 20)) (faults (setting "BOX_FAULT_RUNS" 10)))
    (let loop ((seed (setting "BOX_SEED" 1)) (plain-left plain) (faults-left faults)
               (done '()) (refused '()))
      (if (and (= plain-left 0) (= faults-left 0))
          (summary (reverse done) (reverse refused))
          (let* ((made (generated-layout seed)) (dir (car made)))
            (cond
             ((not dir)
              (say (cut-line (car (text-lines (cdr made)))))
              (loop (+ seed 1) plain-left faults-left done (cons seed refused)))
             (else
              ;; Two without a fault, then one with, while both are left.
              (let* ((fault? (and (> faults-left 0)
                                  (or (= plain-left 0)
                                      (= 2 (modulo (length done) 3)))))
                     (r (run-layout seed dir (cdr made) fault?)))
                (delete-file-hierarchy dir)
                (report r)
                (loop (+ seed 1) (if fault? plain-left (- plain-left 1))
                      (if fault? (- faults-left 1) faults-left)
                      (cons r done) refused)))))))))

(define (summary runs refused)
  (let* ((plain (remove cadr runs)) (faults (filter cadr runs))
         (mms (filter-map (lambda (r) (list-ref r 3)) runs))
         (sims (filter-map (lambda (r) (list-ref r 4)) runs))
         (walls (map (lambda (r) (exact (round (list-ref r 5)))) runs)))
    (say "box-bench: " (length runs) " runs of seeds " (car (car runs)) " to "
         (car (last runs)) "; " (length refused) " layouts refused (seeds "
         refused "); load average " (load-average))
    (for-each (lambda (r) (if (not (list-ref r 2))
                              (say "box-bench: failed: seed " (car r)
                                   (if (cadr r) " (a pusher killed)" ""))))
              runs)
    (say "bench: box-success-rate " (rate plain) " % (" (count caddr plain) " of "
         (length plain) ")")
    (say "bench: box-fault-success-rate " (rate faults) " % (" (count caddr faults) " of "
         (length faults) ")")
    (say "bench: box-goal-error-p50 " (percentile mms 0.5) " mm")
    (say "bench: box-goal-error-p95 " (percentile mms 0.95) " mm")
    (say "bench: box-sim-seconds-p50 " (percentile sims 0.5) " s")
    (say "bench: box-sim-seconds-p95 " (percentile sims 0.95) " s")
    (say "bench: box-wall-seconds-p50 " (percentile walls 0.5) " s")
    (say "bench: box-wall-seconds-p95 " (percentile walls 0.95) " s")))

(define (load-average)
  (let ((words (string-split (car (text-lines (file-text "/proc/loadavg"))) #\space)))
    (string-append (car words) " " (cadr words) " " (caddr words))))

(main)
