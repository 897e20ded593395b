;;;; Publish/subscribe and negotiation figures for labs of N address spaces
;;;; on this machine (simulated broadcast):
;;;;   bench: request-latency-NN VALUE ms          a request to all, answered
;;;;                                                by every address space
;;;;   bench: request-cpu-NN VALUE us              the CPU time that request
;;;;                                                took in all the lab's
;;;;                                                processes, per address space
;;;;   bench: request-receiver-cpu-NN VALUE us     the same requests' CPU in
;;;;                                                the address spaces alone,
;;;;                                                per address space: a
;;;;                                                receiver's, beside bare
;;;;                                                Chibi's echo server's
;;;;                                                (chibi-echo-cpu-per-frame)
;;;;   bench: request-sender-cpu-NN VALUE us       the requester's own CPU
;;;;                                                time per request
;;;;   bench: pose-task-negotiation-NN VALUE ms    pose-task's negotiation of
;;;;                                                the dual-sonar task
;; The latency of a lab larger than the machine's cores is its CPU time
;; shared out; request-cpu shows whether the work grows with N.
;; Two address spaces stand in for the robots (workstations with mobile
;; and sonar, at the thesis's robot positions), so that the figure is the
;; negotiation's, not the simulator's; the rest are workstations.
;; Medians over many runs.  Usage: tools/chibi bench/pubsub.scm N [multicast]
;; (one lab a process: an address space joins one lab); bench/run runs 4, 16
;; and 64, by simulated broadcast and by multicast (NAME-mcast-NN).
;; The lab is started as a user starts one, by `murdoch lab` (all but the
;; bencher, which is this process), whose address spaces are forks of its
;; loader.  With "scale" after N (bench/scale) it also prints
;; lab-start-seconds-NN, from `murdoch lab` to its "lab: ready", and
;; aspace-rss-mb-NN and aspace-pss-mb-NN, the median address space's
;; resident memory, and its proportional share of it (a page it shares with
;; k others counts 1/(k+1)).
;; With "busy SECONDS" after N it measures nothing: it prints "busy" and the
;; lab's pids, sends requests to all back to back for that long, then prints
;; "requests K in SECONDS s", for bench/profile to sample the lab meanwhile.

(import (except (scheme base) lambda define) (scheme write) (scheme time) (scheme eval)
        (scheme process-context) (scheme file) (srfi 1) (srfi 132)
        (only (chibi process) current-process-id system?)
        (only (murdoch robot trip) split-words) (scheme read)
        (only (chibi string) string-prefix?)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness)
        (bench clock))

(define (aspace-clause i)
  (let ((name (string->symbol (string-append "w" (number->string i)))))
    (case i
      ((1) `(aspace ,name (position 1200 -400 180) (capabilities mobile sonar)
                    (load 0.5)))
      ((2) `(aspace ,name (position -1800 -600 90) (capabilities mobile sonar)
                    (load 0.5)))
      (else `(aspace ,name (position 0 0 0) (load ,(/ i 100.)))))))

(define lab-pids '())

(define (start-lab n delivery)
  (let* ((lab (make-test-lab
               `((code ,(tool-path "examples/dual-sonar.scm")) ,@delivery
                 ,@(if scale? (scale-settings n) '())
                 (aspace bencher)
                 ,@(map aspace-clause (iota n 1)))))
         (dir (test-lab-directory lab))
         (out (string-append dir "/lab.out")))
    (if scale? (move-lab! lab scale-port-base))
    (let* ((started (current-second))
           (pid (start-process! (list (tool-path "bin/murdoch") "lab" (test-lab-file lab)
                                      "--except" "bencher"
                                      "--logs" (string-append dir "/logs"))
                                out)))
      ;; Sixty-four address spaces starting at once took a minute of two
      ;; cores, more while others' tests ran, when each loaded Murdoch.
      (wait-until 900 (lambda ()
                        (let ((text (file-text out)))
                          (or (text-contains? text "lab: ready")
                              (text-contains? text "stopping the lab")))))
      (if (not (text-contains? (file-text out) "lab: ready"))
          (begin (stop-all-processes!)
                 (error "the lab did not start; see its output" out (file-text out))))
      (if scale? (report "lab-start-seconds" n (- (current-second) started) "s"))
      (set! lab-pids (aspace-pids pid (string-append dir "/pids")))
      (if (not (= (length lab-pids) n))
          (error "not every address space was found" (length lab-pids) n))
      lab)))

;; The pids of the address spaces w1, w2 ... under process root, as ps
;; names them (murdoch-wN): the lab's loader's children.
(define (aspace-pids root file)
  (system? "sh" "-c" "ps -eo pid=,ppid=,comm= | awk -v root=\"$1\" '
              { up[$1] = $2; name[$1] = $3 }
              END { for (p in up) { q = p
                                    while (q in up && q != root) q = up[q]
                                    if (q == root && name[p] ~ /^murdoch-w[0-9]/)
                                      print p } }
            ' >\"$2\""
           "pids" (number->string root) file)
  (map string->number (read-lines file)))

;;; bench-scale: labs of 64 to 256 (bench/scale)

;; A lab past 64 on one host needs more connections than the lab's
;; defaults allow from one host: the requester's to each, and each one's
;; back to the requester.
(define (scale-settings n)
  `((max-connections ,(* 2 (+ n 8))) (max-connections-per-host ,(* 2 (+ n 8)))))

;; Ports past 200 from a base would run into the next base that
;; tools/free-port-base hands out, so a lab of more is put below its
;; range, at MURDOCH_SCALE_PORT_BASE (default 7000): one bench-scale at
;; a time on a machine.
(define scale-port-base
  (string->number (or (get-environment-variable "MURDOCH_SCALE_PORT_BASE")
                      "7000")))

(define (move-lab! lab base)
  (let* ((file (test-lab-file lab))
         (form (call-with-input-file file read)))
    (call-with-output-file file
      (lambda (out)
        (write-simple (map (lambda (clause)
                             (if (and (pair? clause) (eq? (car clause) 'port-base))
                                 (list 'port-base base)
                                 clause))
                           form)
                      out)))))

;; The MB of memory that the line of Linux's /proc/PID/FILE starting with
;; field says process pid has: its resident set in status (VmRSS), its
;; proportional share of it in smaps_rollup (Pss).
(define (memory-mb pid file field)
  (call-with-input-file (string-append "/proc/" (number->string pid) "/" file)
    (lambda (in)
      (let loop ()
        (let ((line (read-line in)))
          (cond ((eof-object? line) 0)
                ((string-prefix? field line)
                 (/ (string->number (cadr (split-words line))) 1024.))
                (else (loop))))))))

(define (report-resident n)
  (define (median-mb file field)
    (let ((mbs (list-sort < (map (lambda (pid) (memory-mb pid file field)) lab-pids))))
      (list-ref mbs (quotient (length mbs) 2))))
  (report "aspace-rss-mb" n (median-mb "status" "VmRSS:") "MB")
  (report "aspace-pss-mb" n (median-mb "smaps_rollup" "Pss:") "MB"))

(define (median-ms runs thunk) (* 1000 (median-seconds runs thunk)))

(define (report name n value unit)
  (display "bench: ") (display name) (display suffix) (display n) (display " ")
  (display (/ (round (* 100 value)) 100.)) (display " ") (display unit)
  (newline))

;; Seconds of CPU, user and system, that process pid has used (Linux's
;; /proc/PID/stat, in clock ticks of 1/100 s).
(define (cpu-seconds pid)
  (let* ((text (call-with-input-file (string-append "/proc/" (number->string pid)
                                                    "/stat")
                 (lambda (in) (read-line in))))
         (fields (let after-name ((i (- (string-length text) 1)))
                   (if (char=? (string-ref text i) #\))
                       (split-words (substring text (+ i 2) (string-length text)))
                       (after-name (- i 1))))))
    ;; utime and stime are fields 14 and 15; the list starts at field 3.
    (/ (+ (string->number (list-ref fields 11)) (string->number (list-ref fields 12)))
       100.)))

(define (lab-cpu-seconds)
  (apply + (cpu-seconds (current-process-id)) (map cpu-seconds lab-pids)))

;; Microseconds of this process's own CPU, the requester's, per request:
;; what multicast saves on a real network, where each receiver has a CPU
;; of its own.  All its threads count: those that read the answers too.
(define (request-sender-cpu-us runs)
  (let ((before (own-cpu-us)))
    (do ((i 0 (+ i 1))) ((= i runs)) (request 'all (lambda () #t)))
    (/ (- (own-cpu-us) before) runs)))

;; Microseconds of CPU per request per address space: in the whole lab,
;; and in the address spaces alone, the receivers (by their schedulers'
;; count, exact where /proc/PID/stat's ticks of 10 ms are not: a
;; receiver spends about one tick over the runs at 64).
(define (report-request-cpu n runs)
  (let ((before (lab-cpu-seconds))
        (receivers-before (processes-cpu-us lab-pids)))
    (do ((i 0 (+ i 1))) ((= i runs)) (request 'all (lambda () #t)))
    (let ((receivers (- (processes-cpu-us lab-pids) receivers-before)))
      (report "request-cpu" n (/ (* 1000000 (- (lab-cpu-seconds) before)) runs n) "us")
      (report "request-receiver-cpu" n (/ receivers runs n) "us"))))

(define (negotiate-and-release task)
  (let ((team (apply negotiate task)))
    (if (symbol? team) (error "negotiation failed" team))
    (for-each (lambda (winner type)
                (if (eq? type 'exclusive) ((cadr winner) #f)))
              (car team) (cadr team))))

(define (measure-lab n)
  (let ((task (eval '(dual-sonar-task) (lab-environment))))
    (median-ms 5 (lambda () (request 'all (lambda () #t))))    ; warm-up
    ;; A lab of hundreds connects one address space after another within
    ;; a request's timeout; on a loaded machine it takes a few requests,
    ;; given a minute each: a lab of 256 forked within a minute still had
    ;; 186 without a welcome after 30 tries of 5 s.
    (let warm ((tries 30))
      (if (and (> tries 0)
               (< (length (parameterize ((remote-timeout 60))
                            (request 'all (lambda () #t))))
                  n))
          (warm (- tries 1))))
    (report "request-latency" n
            (median-ms 50 (lambda ()
                            (let ((answers (request 'all (lambda () #t))))
                              (if (< (length answers) n)
                                  (error "not every address space answered"
                                         (length answers))))))
            "ms")
    (report-request-cpu n (quotient 4000 n))
    (report "request-sender-cpu" n (request-sender-cpu-us (quotient 16000 n)) "us")
    (report "pose-task-negotiation" n
            (median-ms 20 (lambda () (negotiate-and-release task)))
            "ms")))

(define (keep-busy seconds)
  (do ((i 0 (+ i 1))) ((= i 20)) (request 'all (lambda () #t)))  ; warm-up
  (display "busy")
  (for-each (lambda (pid) (display " ") (display pid)) lab-pids)
  (newline)
  (flush-output-port)
  (let ((end (+ (current-second) seconds)))
    (let loop ((k 0))
      (cond ((< (current-second) end)
             (request 'all (lambda () #t))
             (loop (+ k 1)))
            (else (display "requests ") (display k) (display " in ")
                  (display seconds) (display " s") (newline))))))

;; The lab's address spaces are stopped however the measuring ends.
(define (bench-lab n delivery busy-seconds)
  (let* ((lab (start-lab n delivery))
         (done (lambda () (stop-all-processes!) (remove-test-lab! lab))))
    (guard (e (#t (done) (raise e)))
      (join-lab (test-lab-file lab) 'bencher)
      (if busy-seconds (keep-busy busy-seconds) (measure-lab n))
      (if scale? (report-resident n)))
    (done)))

(define options (cddr (command-line)))
(define multicast? (member "multicast" options))
(define scale? (member "scale" options))
(define suffix (if multicast? "-mcast-N" "-N"))
(bench-lab (string->number (cadr (command-line)))
           (if multicast? '((delivery multicast "239.255.77.7")) '())
           (let ((busy (member "busy" options)))
             (and busy (pair? (cdr busy)) (string->number (cadr busy)))))
