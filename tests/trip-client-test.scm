;;; The Scheme trip client against a real sim/b14 (built beforehand).
(import (scheme base) (scheme write) (scheme read) (scheme file) (scheme inexact)
        (srfi 18) (chibi test)
        (scheme process-context)
        (only (chibi process) system? kill signal/term current-process-id)
        (chibi net) (only (chibi filesystem) open-input-file-descriptor)
        (murdoch code abandon) (murdoch robot trip))

;; Start b14 in the background on free ports in a fresh folder, wait
;; (boundedly) for its ready line, and leave "(DIR PORT-BASE PID)" in a file.
;; A watchdog ends b14 and removes the folder when this test process ends,
;; however that happens.  (system, not process->string: the latter leaves
;; descriptors behind whose finalizers close our sockets later.)
(define state-file
  (string-append (or (get-environment-variable "TMPDIR") "/tmp")
                 "/trip-client-test." (number->string (current-process-id))))

(define (start-b14!)
  (system? "sh" "-c"
           "set -e
            b14=\"$PWD/sim/b14\" base=$(tools/free-port-base) dir=$(mktemp -d)
            cd \"$dir\"
            cat > lab.scm <<'LAB'
(lab t
  (aspace moseley (robot (pose 0 0 0)))
  (aspace troy (position -1524 -2743.2 90))
  (aspace ernst (robot (pose -2000 0 180) (battery 13.4)))
  (world (wall -3000 -3000 3000 -3000) (wall 3000 -3000 3000 3000)
         (wall 3000 3000 -3000 3000) (wall -3000 3000 -3000 -3000)
         (box 1800 1800 600 600 0)
         (box 2500 -500 600 600 0) (wall 1500 -1200 1500 600))
  (simulator (speed 10)))
LAB
            \"$b14\" lab.scm --port-base $base --lock-dir locks >out 2>err &
            pid=$!
            ( while kill -0 \"$2\" && kill -0 $pid; do sleep 0.2; done
              kill $pid; rm -rf \"$dir\" ) >/dev/null 2>&1 &
            i=0
            until grep -q '^b14: ready' out 2>/dev/null; do
              i=$((i+1)); [ $i -lt 400 ]; sleep 0.05
            done
            echo \"(\\\"$dir\\\" $base $pid)\" > \"$1\""
           "start-b14" state-file (number->string (current-process-id)))
  (let ((state (with-input-from-file state-file read)))
    (delete-file state-file)
    state))

(define b14 (start-b14!))
(define port-base (cadr b14))
(define b14-pid (car (cddr b14)))

(define (stop-b14!) (kill b14-pid signal/term))

(define moseley-port (+ port-base 100))      ; aspace 0
(define ernst-port (+ port-base 102))        ; aspace 2: troy counts too

(define (every-in? ls lo hi)
  (or (null? ls) (and (<= lo (car ls) hi) (every-in? (cdr ls) lo hi))))
(define (near? a b tolerance) (< (abs (- a b)) tolerance))
(define (error-of thunk)
  (guard (e ((trip-error? e) (list (trip-error-code e) (trip-error-text e))))
    (thunk)
    'no-error))

(test-begin "trip-client")

(define moseley (trip-connect "127.0.0.1" moseley-port))
(define ernst (trip-connect "127.0.0.1" ernst-port))

(test-group "connection"
  (test-assert (trip-connection? moseley))
  (test "who" '("moseley" "b14-sim") (trip-request moseley 'who))
  (test "the port of aspace 2 is ernst's" '("ernst" "b14-sim") (trip-request ernst 'who)))

(set-current-robot! moseley)

(test-group "motion"
  (test-assert "im opens every device" (im))
  (test "reckon at the start" '(0 0 0 0) (map exact (map round (reckon))))
  (let ((p (goto-xy '(300 200))))
    (test-assert "goto-xy arrives within 2 cm"
      (< (sqrt (+ (square (- (car p) 300)) (square (- (cadr p) 200)))) 20))
    (test "goto-xy answers as reckon" 4 (length p)))
  (let ((p (rotate 'by (angle-to-heading 90))))
    (test-assert "rotate 'by angle-to-heading reaches it within 2 degrees"
      (near? (car (cddr p)) 90 2)))
  (test-assert "rotate 'to" (near? (car (cddr (rotate 'to -45))) -45 2))
  (test "angle-to-heading takes the short way" -90
        (exact (round (angle-to-heading -135))))
  (set-reckon-position! 0 0)
  (set-reckon-heading! 0)
  (test "set-reckon-position! and -heading! make a new origin" '(0 0 0 0)
        (map exact (map round (reckon))))
  (let ((p (translate 100)))
    (test-assert "translate along the new heading" (near? (car p) 100 5))))

(test-group "the robot's clock"
  ;; robot-time is the simulator's T time, in seconds: it lies between two
  ;; readings of T time around it, and runs on while the robot moves.
  (let* ((before (car (trip-request moseley 'time))) (t (robot-time))
         (after (car (trip-request moseley 'time))))
    (test "between the simulator's own readings" '()
      (if (<= (/ before 1000.) t (/ after 1000.)) '() (list before t after)))
    (translate 50)
    (test-assert "later after a motion" (> (robot-time) t))))

(test-group "sensors"
  (sonar-start)
  (let ((r (sonar-read)))
    (test "sonar-read gives 16 ranges" 16 (length r))
    (test-assert "in range" (every-in? r 150 6500)))
  (sonar-stop)
  (test-assert "after sonar-stop the reading stays" (= 16 (length (sonar-read))))
  (test "ir-read" 16 (length (ir-read)))
  (test "bumpers-read" 12 (length (bumpers-read)))
  (test "skirt-read" 6 (length (skirt-read)))
  (test-assert "lights" (lights 1 0 #t #f))
  (test "lights read back" '(1 0 1 0) (lights))
  (test-assert "say" (say "moving to" '(300 200)))
  (let ((v (battery-voltage)))
    (test-assert "battery-voltage in tenths of a volt"
      (and (exact-integer? v) (<= 130 v 137))))
  (trip-request ernst 'buttons 'press 1)
  (test "a button pressed by another client" '(0 0 0 0) (buttons-read))
  (trip-request moseley 'buttons 'press 1)
  (test "a button pressed on this robot" '(0 1 0 0) (buttons-read)))

(test-group "the fiducial finder"
  ;; After the motion tests moseley stands near (371 129), heading -45.
  ;; Turned to 45, box 0 (centre (1800 1800), heading 0) is 2199 mm away,
  ;; 4.5 degrees to the left, turned -45 from the robot; box 1 is in the
  ;; field of view too (62 degrees right) but behind the wall at x = 1500.
  (rotate 'by 90)
  (let ((seen (fiducials)))
    (test "facing them, one box seen, the lab's first: the other is behind a wall"
          '(0) (map fiducial-id seen))
    (test-assert "each as (ID RANGE BEARING ORIENTATION), id and range integers"
      (and (= 4 (length (car seen))) (exact-integer? (fiducial-id (car seen)))
           (exact-integer? (fiducial-range (car seen)))))
    (test-assert "its range, from here, in mm"
      (near? (fiducial-range (car seen)) 2199 60))
    (test-assert "its bearing, from the heading, in degrees"
      (near? (fiducial-bearing (car seen)) 4.5 5))
    (test-assert "its orientation relative to the robot's"
      (near? (fiducial-orientation (car seen)) -45 3)))
  (rotate 'by 180)
  (test "facing away, none" '() (fiducials)))

(test-group "sonar against a wall"
  (parameterize ((current-robot ernst))
    ;; ernst faces the wall at x = -3000 (face at -2975) from x = -2000
    (test-assert "sonar 0 reads the distance from the skin within the noise"
      (near? (car (sonar-read)) (- 975 180) 40))
    (test "battery" 134 (battery-voltage))))

(test-group "exclusion"
  (let ((second (trip-connect "127.0.0.1" moseley-port)))
    (test "a device held by another connection is refused, by name"
          '(held "base is held by another client")
          (parameterize ((current-robot second)) (error-of reckon)))
    (trip-close moseley)
    (test-assert "closing the holder frees it"
      (let retry ((n 0))
        (or (guard (e ((and (trip-error? e) (< n 100)) (thread-sleep! 0.05) #f))
              (parameterize ((current-robot second)) (reckon)) #t)
            (retry (+ n 1)))))
    (set! moseley second)
    (set-current-robot! second)))

(test-group "errors"
  (test "bad arguments" '(args "x is not a number")
    (error-of (lambda () (rotate 'by 'x))))
  (test "unknown command" 'unknown
        (car (error-of (lambda () (trip-request moseley 'base 'fly)))))
  (test-error "rotate needs 'by or 'to" (rotate 'sideways 10))
  (let ((mute (make-listener-socket
               (get-address-info "127.0.0.1" (+ port-base 150)))))
    (test "a server that never answers times out" 'timeout
          (parameterize ((trip-timeout 0.3))
            (car (error-of (lambda () (trip-connect "127.0.0.1" (+ port-base 150)))))))
    ;; Closed only here: a listener nothing refers to any more may be
    ;; collected, and its socket closed, in the middle of the test.
    (close-port (open-input-file-descriptor mute)))
  (test "nobody listening" 'closed
        (car (error-of (lambda () (trip-connect "127.0.0.1" (+ port-base 151)))))))

(test-group "concurrent callers share a connection"
  (let* ((results '())
         (workers (map (lambda (k)
                         (make-thread
                          (lambda ()
                            (do ((i 0 (+ i 1))) ((= i 20))
                              (let ((n (length (reckon))))
                                (set! results (cons n results)))))))
                       '(1 2 3))))
    (for-each thread-start! workers)
    (for-each thread-join! workers)
    (test "every call got its own reply" #t (equal? (make-list 60 4) results))))

(test-group "a call whose caller gave up"
  ;; Ten turns take the simulated robot a minute, six seconds here.
  (let ((turner (make-thread
                 (lambda ()
                   (guard (e ((abandoned-error? e) (error-object-message e)))
                     (rotate 'by 3600))))))
    (thread-start! turner)
    (thread-sleep! 0.3)
    (abandon-thread! turner)
    (test "a motion stops, saying why" "rotate: stopped, its caller gave up"
          (thread-join! turner))
    (forget-abandoned! turner))
  (let ((heading (car (cddr (reckon)))))
    (thread-sleep! 0.3)
    (test-assert "and the robot stands still"
      (near? (car (cddr (reckon))) heading 0.5)))
  (abandon-thread! (current-thread))
  (test "any other command raises in it" #t
        (guard (e ((abandoned-error? e) #t)) (reckon) #f))
  (forget-abandoned! (current-thread))
  (test "and works again once the call is over" 4 (length (reckon))))

(define (turned-from start heading)
  (let ((a (- heading start)))
    (abs (- a (* 360 (round (/ a 360)))))))

(test-group "waiting for a motion"
  ;; Two turns take the simulated robot 12 s, 1.2 s here.  Its connection
  ;; is not held while the turner waits for the end (base await).
  (let* ((start (car (cddr (reckon))))
         (turner (make-thread (lambda () (rotate 'by 720)))))
    (thread-start! turner)
    (let ((status (let look ((n 0))     ; until a quarter turn shows
                    (let ((status (trip-request moseley 'base 'status)))
                      (if (or (> (turned-from start (car (cddr status))) 90) (> n 500))
                          status
                          (begin (thread-sleep! 0.01) (look (+ n 1))))))))
      (test "another thread's request is answered while the motion goes on" 1
            (list-ref status 5))
      (let ((end (thread-join! turner)))
        (test "then the turner has the pose the motion ended at"
              (map round (reckon)) (map round end))
        (test-assert "two whole turns" (< (turned-from start (car (cddr end))) 2)))))
  (test "a motion over its time is stopped, and says so" '(timeout "motion took too long")
        (parameterize ((trip-motion-timeout 0.2))
          (error-of (lambda () (rotate 'by 720)))))
  (test "and the base stands still" 0 (list-ref (trip-request moseley 'base 'status) 5)))

(test-group "safe.scm"
  (test-assert "safe-reckon on a robot is reckon" (= 4 (length (safe-reckon '(1 2 3)))))
  (parameterize ((current-robot #f))
    (test "safe-battery-voltage on a workstation" 140 (safe-battery-voltage))
    (test "safe-reckon on a workstation: its position" '(-1524 -2743.2 90 0)
          (safe-reckon '(-1524 -2743.2 90)))
    (test "safe-reckon without a position" #f (safe-reckon))
    (workstation-position '(-1524 -2743.2 90))
    (test "safe-reckon from workstation-position" '(-1524 -2743.2 90 0) (safe-reckon))
    (workstation-position #f)
    (test-assert "safe-im on a workstation" (safe-im))
    (test-error "a primitive without a robot" (reckon))))

(test-group "the server goes away"
  (stop-b14!)
  (test "requests then fail as closed" 'closed
        (let retry ((n 0))
          (let ((e (error-of reckon)))
            (if (or (and (pair? e) (eq? (car e) 'closed)) (> n 100))
                (if (pair? e) (car e) e)
                (begin (thread-sleep! 0.05) (retry (+ n 1))))))))

(test-end)
(test-exit)
