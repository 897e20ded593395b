;;;; The remote layer's figures: remote-apply round trips and remote-run!
;;;; throughput between two address spaces on this machine.
;;
;; Prints, one line each, medians over many calls after a warm-up:
;;   bench: remote-apply-rtt VALUE us       a trivial closure
;;   bench: remote-apply-rtt-1k VALUE us    a closure capturing 1 KB
;;   bench: remote-run-throughput VALUE per-s          16 sender threads
;;   bench: remote-run-throughput-serial VALUE per-s   one, each call waiting
;;                                                      for its ack
;; The C floor (bench/c-pingpong) and the ratio are printed by bench/run.
;; With the argument "round", only remote-apply-rtt and
;; remote-run-throughput, on fewer calls: one round of bench/run's
;; comparisons with their Chibi floors.

(import (except (scheme base) lambda define) (scheme write) (scheme time)
        (scheme process-context)
        (srfi 1) (srfi 18) (srfi 132)
        (murdoch) (murdoch cli command) (murdoch testing harness))

(define lab (make-test-lab '((aspace bencher) (aspace troy))))

(define troy-pid
  (start-process! (list (tool-path "bin/murdoch") "aspace"
                        (test-lab-file lab) "troy")
                  (string-append (test-lab-directory lab) "/troy.log")))
(wait-for-port (+ 1 (test-lab-port-base lab)) 20)
(join-lab (test-lab-file lab) 'bencher)

(define (median-us calls thunk) (* 1000000 (median-seconds calls thunk)))

(define (report name value unit)
  (display "bench: ") (display name) (display " ")
  (display (/ (round (* 10 value)) 10.)) (display " ") (display unit)
  (newline))

(define troy (uid->aspace 'troy))


(define round? (member "round" (command-line)))

(median-us 200 (lambda () (remote-apply troy (lambda () 1))))   ; warm-up
(report "remote-apply-rtt"
        (median-us (if round? 1000 3000) (lambda () (remote-apply troy (lambda () 1))))
        "us")
(unless round?
 (let ((kilobyte (make-string 1024 #\m)))
  (report "remote-apply-rtt-1k"
          (median-us 3000 (lambda ()
                            (remote-apply troy
                                          (lambda () (string-length kilobyte)))))
          "us")))
;; remote-run! returns once the target has acknowledged, so one thread's
;; calls are a round trip each; a sender with work to hand out keeps
;; several on the way, and the acks of a burst come back in one write.
(define (run-throughput threads calls)
  (let ((t0 (current-second)))
    (for-each thread-join!
              (map (lambda (i)
                     (thread-start!
                      (make-thread
                       (lambda ()
                         (do ((i 0 (+ i 1))) ((= i calls))
                           (remote-run! troy (lambda () #t)))))))
                   (iota threads)))
    (/ (* threads calls) (- (current-second) t0))))

;; The warm-up is long enough for the processes' heaps to have grown to
;; the calls: after 1,600 calls a round of 4,000 read 8,300 to 10,000 a
;; second, where 5,600 calls first gave 15,000, as the whole run's, whose
;; round trips before it warm it up too.  The 16,000 calls measured take
;; in several collections at each end, as a steady stream does: each end
;; collects every 3,000 to 5,000 calls, and rounds of 4,000 read 40,000
;; to 90,000 a second as one fell in them or none did.
(run-throughput 16 350)                                          ; warm-up
(report "remote-run-throughput" (run-throughput 16 1000) "per-s")
(unless round?
  (report "remote-run-throughput-serial" (run-throughput 1 5000) "per-s"))

(stop-all-processes!)
(remove-test-lab! lab)
