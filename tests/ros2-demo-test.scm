;;; `make demo ROS2=1`: the dual-sonar task with every robot reached through
;;; ROS 2 (address space -> trip -> trip_ros2 -> ROS 2 -> the simulator's
;;; face -> sim/b14) ends as `make demo` does: the same winners, and sonar
;;; readings taken where the direct run took them.
(import (scheme base) (scheme write) (scheme read) (scheme file)
        (srfi 1) (chibi test)
        (only (chibi process) system)
        (murdoch testing harness))

(if (not (file-exists? (tool-path ".deps/ros2/bin/python")))
    (begin (display "skipped: no ROS 2 in .deps/ros2 (make deps installs it)\n")
           (exit 0)))

(define dir (temporary-directory))
(define base (free-port-base dir))

;; (exit-status output) of `bin/murdoch demo` of the Tulane lab, with
;; MURDOCH_ROS2 set to ros2.
(define (demo ros2 name)
  (let ((status (system "sh" "-c"
                        (string-append "cd \"$1\" && MURDOCH_ROS2=$2 MURDOCH_PORT_BASE=$3"
                                       " timeout -s KILL 200 \"$0/bin/murdoch\" demo"
                                       " \"$0/examples/tulane-lab.scm\" >$4 2>&1")
                        (tool-path ".") dir ros2 (number->string base) name)))
    (list (quotient (if (pair? status) (cadr status) status) 256)
          (file-text (string-append dir "/" name)))))

(define (lines-with word text)
  (filter (lambda (l) (text-contains? l word)) (text-lines text)))

;; The task's result: the last line that reads as a list of three lists.
(define (result text)
  (let loop ((ls (reverse (text-lines text))))
    (cond ((null? ls) #f)
          ((and (> (string-length (car ls)) 2) (string=? "((" (substring (car ls) 0 2)))
           (read (open-input-string (car ls))))
          (else (loop (cdr ls))))))

;; The lab's logs folder, as `murdoch lab` says it.
(define (logs-of text)
  (let ((line (find (lambda (l) (text-contains? l "lab: logs in ")) (text-lines text))))
    (if line (substring line (string-length "lab: logs in ") (string-length line)) "")))

(test-begin "ros2-demo")

(define direct (demo "" "direct.out"))
(define through (demo "1" "ros2.out"))

(test-group "the dual-sonar task through ROS 2"
  (test "the direct run completes" 0 (car direct))
  (test "the run through ROS 2 completes" 0 (car through))
  (let ((logs (logs-of (cadr through))))
    (test "its robots were reached through their trip servers, over the face"
          '(#t #t #t)
          (map (lambda (file word) (text-contains? (file-text (string-append logs "/" file))
                                                   word))
               '("trip-moseley.log" "trip-ernst.log" "face.log")
               '("trip-ros2: ready" "trip-ros2: ready" "b14-face: ready"))))
  (test "the same winners" (lines-with "goes to" (cadr direct))
        (lines-with "goes to" (cadr through)))
  (let ((a (result (cadr direct))) (b (result (cadr through))))
    (test-assert "both answer two sonar rings and a sorted list"
      (and a b (= 3 (length a)) (= 3 (length b))))
    ;; Each ring is the B14's sixteen sectors, read at its target.  Both
    ;; runs stop within a millimetre of it, so most sectors differ by the
    ;; sonar's noise (10 mm, a fresh draw in each run): 80 mm, or 3 % of a
    ;; far echo's range.  A few may not: the other robot may still be on its
    ;; way when one reads (ROS 2 times the two robots differently), and the
    ;; two controllers end a few tenths of a degree apart, which moves a far
    ;; echo off a glancing wall by more than 3 % (a clean-clone run: 122 mm
    ;; at 3.3 m, 163 mm at 4.8 m).  A ring read elsewhere, or mid-turn,
    ;; differs in many of its sectors.
    (test "each sonar ring is sixteen ranges" '(#t #t)
          (map (lambda (ring) (and (list? ring) (= 16 (length ring)) (every real? ring)))
               (take b 2)))
    (test "each sonar ring near the direct run's in all but four sectors" '()
          (filter-map (lambda (ring-a ring-b i)
                        (let ((near (lambda (x y) (< (abs (- x y)) (max 80 (* 0.03 x))))))
                          (and (> (count (lambda (x y) (not (near x y))) ring-a ring-b) 4)
                               (list i ring-a ring-b))))
                      (take a 2) (take b 2) '(1 2)))))

(test-end)
(test-exit)
