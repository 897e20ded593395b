;;; Robots reached through ROS 2 (docs/ros2.md): two unicycles written for
;;; this test (tests/ros2/unicycle.py, not the simulator), each with its
;;; trip server robot/ros2/trip_ros2.py, which `murdoch lab` starts.  The
;;; trip protocol against that server; goto-xy and sonar-read from an
;;; address space; its faults (odometry that stops, a trip server killed,
;;; a cmd_vel of the wrong type, a robot that never appears); and every
;;; ROS 2 process on loopback alone.
(import (except (scheme base) lambda define) (scheme write) (scheme eval)
        (scheme file) (scheme process-context) (scheme inexact)
        (srfi 1) (srfi 18) (chibi test)
        (only (chibi process) kill signal/kill)
        (only (chibi string) string-prefix?)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness)
        (murdoch wire connect) (only (murdoch robot trip) trip-connect trip-request trip-close))

(if (not (file-exists? (tool-path ".deps/ros2/bin/python")))
    (begin (display "skipped: no ROS 2 in .deps/ros2 (make deps installs it)\n")
           (exit 0)))

(define lab-code "
;; Drives to (x y), faces heading h, and answers the pose and the sonar.
(define (go-and-read x y h)
  (sonar-start)
  (goto-xy (list x y))
  (rotate 'to h)
  (list (reckon) (sonar-read)))
;; Drives far, for the fault of odometry that stops.
(define (drive-far)
  (goto-xy '(2000 0))
  (local-aspace-uid))
(define (pose-now) (reckon))
;; Drives toward (x y): the error's message if trip refuses, else arrived.
(define (try-goto x y)
  (guard (e ((error-object? e) (error-object-message e)))
    (goto-xy (list x y))
    'arrived))
")

(define lab
  (make-test-lab
   '((code "code.scm") (heartbeat 0.3)
     (aspace tester)
     (aspace tb1 (robot (pose 0 0 0)
                        (ros2 (namespace "/tb1") (cmd-vel twist) (appear-timeout 40)))
             (capabilities mobile sonar))
     (aspace tb2 (robot (pose 0 1000 0) (ros2 (namespace "/tb2") (appear-timeout 40)))
             (capabilities mobile sonar)))
   `(("code.scm" . ,lab-code))))

(define (in-dir name) (string-append (test-lab-directory lab) "/" name))
(define base (number->string (test-lab-port-base lab)))

;; A unicycle of the test under namespace ns, its cmd_vel of type cmd-vel.
(define (start-unicycle! ns cmd-vel . more)
  (let* ((log (in-dir (string-append "unicycle-" ns ".log")))
         (pid (start-process!
               (append (list (tool-path "tools/ros2-env") base "python3"
                             (tool-path "tests/ros2/unicycle.py") "--namespace"
                             (string-append "/" ns) "--cmd-vel" cmd-vel "--half" "3000")
                       more)
               log)))
    (wait-until 30 (lambda () (text-contains? (file-text log) "unicycle: ready")))
    pid))

(define tb1-robot (start-unicycle! "tb1" "twist" "--pose" "0" "0" "0" "--battery" "12.3"))
(define tb2-robot (start-unicycle! "tb2" "stamped" "--pose" "0" "1000" "0"))

;; For the protocol's tests, a trip server of tb2 of their own, before the
;; lab's address space holds tb2's devices.
(define raw-port (+ (test-lab-port-base lab) 150))
(define raw-server
  (let* ((log (in-dir "trip-raw.log"))
         (pid (start-process! (list (tool-path "tools/ros2-env") base "python3"
                                    (tool-path "robot/ros2/trip_ros2.py") "--name" "tb2"
                                    "--port" (number->string raw-port) "--namespace" "/tb2"
                                    "--lock-dir" (in-dir "raw-locks"))
                              log)))
    (wait-until 30 (lambda () (text-contains? (file-text log) "trip-ros2: ready")))
    pid))

;;; Raw trip, frame by frame

(define (frame payload)
  (let ((out (open-output-bytevector)))
    (write-u8 2 out)
    (for-each (lambda (b)
                (if (memv b '(2 3 16))
                    (begin (write-u8 16 out) (write-u8 (bitwise-xor* b 64) out))
                    (write-u8 b out)))
              (bytevector->list* (string->utf8 payload)))
    (write-u8 3 out)
    (get-output-bytevector out)))

(define (bitwise-xor* a b)
  (let loop ((a a) (b b) (bit 1) (acc 0))
    (if (and (zero? a) (zero? b))
        acc
        (loop (quotient a 2) (quotient b 2) (* bit 2)
              (if (= (modulo a 2) (modulo b 2)) acc (+ acc bit))))))

(define (bytevector->list* bv)
  (let loop ((i (- (bytevector-length bv) 1)) (acc '()))
    (if (< i 0) acc (loop (- i 1) (cons (bytevector-u8-ref bv i) acc)))))

(define (dial port)
  (let ((io (open-connection "127.0.0.1" port 5)))
    (if (string? io) (error "cannot connect" port io))
    io))

(define (send-raw! io bytes)
  (write-bytevector bytes (cadr io))
  (flush-output-port (cadr io)))

;; The next frame's payload, unstuffed; "" when the connection ends.
(define (next-reply io)
  (let ((in (car io)))
    (let outside ()
      (let ((b (read-u8 in)))
        (cond ((eof-object? b) "")
              ((not (= b 2)) (outside))
              (else
               (let inside ((acc '()))
                 (let ((b (read-u8 in)))
                   (cond ((eof-object? b) "")
                         ((= b 3) (list->string (map integer->char (reverse acc))))
                         ((= b 16) (inside (cons (bitwise-xor* (read-u8 in) 64) acc)))
                         (else (inside (cons b acc))))))))))))

(define (ask io payload)
  (send-raw! io (frame payload))
  (next-reply io))

(define (starts? text prefix) (string-prefix? prefix text))

(define (split-colon s)
  (let loop ((cs (string->list s)) (word '()) (acc '()))
    (cond ((null? cs) (reverse (cons (list->string (reverse word)) acc)))
          ((char=? (car cs) #\:) (loop (cdr cs) '() (cons (list->string (reverse word)) acc)))
          (else (loop (cdr cs) (cons (car cs) word) acc)))))


(define (words text)
  (let loop ((cs (string->list text)) (word '()) (acc '()))
    (define (flush) (if (null? word) acc (cons (list->string (reverse word)) acc)))
    (cond ((null? cs) (reverse (flush)))
          ((char=? (car cs) #\space) (loop (cdr cs) '() (flush)))
          (else (loop (cdr cs) (cons (car cs) word) acc)))))

(test-begin "ros2")

(test-group "the trip protocol, served for a ROS 2 robot"
  (let ((c (dial raw-port)) (d (dial raw-port)))
    (test "ping" "1 ok pong" (ask c "1 ping"))
    (test "who names the robot and ros2" "2 ok tb2 ros2" (ask c "2 who"))
    (test-assert "time in milliseconds" (starts? (ask c "3 time") "3 ok "))
    (test "open base" "4 ok" (ask c "4 open base"))
    (test "held by one client, refused to another, by name"
          "1 err held base is held by another client" (ask d "1 open base"))
    (test "a device not open" "2 err not-open open sonar first" (ask d "2 sonar read"))
    (test "a device the robot lacks: unknown, saying so"
          "5 err unknown this robot has no ir (a ROS 2 robot: trip_ros2 maps base, sonar, battery and fiducial)"
          (ask c "5 open ir"))
    (test-assert "no battery topic: battery is unknown, naming the topic"
      (starts? (ask c "6 open battery") "6 err unknown this robot has no battery: nothing publishes /tb2/battery_state"))
    (test "unknown command" "7 err unknown no command or device dance" (ask c "7 dance"))
    (test "unknown command of a device" "8 err unknown base has no command fly"
          (ask c "8 base fly"))
    (test "too few arguments" "9 err args base goto takes 2 numbers" (ask c "9 base goto 1"))
    (test "not a number" "10 err args left is not a number" (ask c "10 base rotate left"))
    (test "no tag" "0 err syntax a request is TAG WORD ..., TAG a number 1 to 999999999"
          (ask c "ping"))
    (send-raw! c (string->utf8 "garbage"))
    (test "bytes outside a frame" "0 err framing byte outside a frame" (ask c "11 ping"))
    (test "and the next frame is fine" "11 ok pong" (next-reply c))
    (send-raw! c (bytevector 2 49 50 32 16 90 3))
    (test "a bad escape" "0 err framing bad escape after DLE" (next-reply c))
    (test "reckon at the start, from odometry" "13 ok 0.0 1000.0 0.00"
          (ask c "13 base reckon"))
    ;; A turn, an await sent after it, and a request after the await: the
    ;; await's reply waits for the motion's end, the other does not.
    (send-raw! c (bytevector-append (frame "14 base rotate 90") (frame "15 base await")
                                    (frame "16 base reckon")))
    (test "the motion is accepted" "14 ok" (next-reply c))
    (test-assert "the request after the await is answered first"
      (starts? (next-reply c) "16 ok "))
    (let ((end (words (next-reply c))))
      (test "then the await, not stalled" '("15" "ok" "0") (list (car end) (cadr end)
                                                              (list-ref end 5)))
      (test-assert "having turned a quarter, on odometry"
        (< (abs (- (string->number (list-ref end 4)) 90)) 1)))
    (test "set-heading" "17 ok" (ask c "17 base set-heading 0"))
    (test-assert "reckon reads it"
      (< (abs (string->number (list-ref (words (ask c "18 base reckon")) 4))) 0.1))
    (test "open sonar" "19 ok" (ask c "19 open sonar"))
    (test "sonar read gives 16 ranges" 18 (length (words (ask c "20 sonar read"))))
    (test "sonar stream on" "21 ok" (ask c "21 sonar stream on"))
    (test-assert "readings stream with tag 0" (starts? (next-reply c) "0 sonar "))
    (ask c "22 sonar stream off")
    (for-each close-port (append d c))
    (let ((e (dial raw-port)))
      (test "a closed connection loses its locks" "1 ok"
            (let retry ((n 0))
              (let ((r (ask e "1 open base")))
                (if (or (equal? r "1 ok") (> n 50)) r
                    (begin (thread-sleep! 0.1) (retry (+ n 1)))))))
      (ask e "2 base set-heading 0")
      (for-each close-port e))))

(stop-process! raw-server)
(define lab-pid
  (start-murdoch-lab! (list (test-lab-file lab) "--except" "tester" "--logs" (in-dir "logs"))
                      (in-dir "lab.out")))
(join-lab (test-lab-file lab) 'tester)
(define (lab-proc name) (eval name (lab-environment)))

(test-group "goto-xy and sonar-read from an address space"
  (let* ((r (parameterize ((remote-timeout 60))
              (remote-apply (uid->aspace 'tb1) (lab-proc 'go-and-read) 1000 500 0)))
         (pose (car r)) (sonar (cadr r)))
    (test-assert "it ends within 2 cm of (1000 500)"
      (< (sqrt (+ (square (- (car pose) 1000)) (square (- (cadr pose) 500)))) 20))
    (test-assert "facing 0" (< (abs (car (cddr pose))) 1))
    ;; The room's walls are at x, y = +-3000; sonar i faces 22.5 i degrees.
    (test-assert "sonar 0, ahead: the wall at x = 3000, 2 m away"
      (< (abs (- (list-ref sonar 0) 2000)) 30))
    (test-assert "sonar 4, left: the wall at y = 3000"
      (< (abs (- (list-ref sonar 4) 2500)) 30))
    (test-assert "sonar 8, behind: the wall at x = -3000"
      (< (abs (- (list-ref sonar 8) 4000)) 30))
    (test-assert "sonar 12, right: the wall at y = -3000"
      (< (abs (- (list-ref sonar 12) 3500)) 30))
    (test "the battery from BatteryState, in tenths of a volt" 123
          (remote-apply (uid->aspace 'tb1)
                        (eval '(lambda () (battery-voltage)) (lab-environment))))))

(test-group "the trip server killed: the lab starts it again, and the client reconnects"
  (let* ((log (in-dir "logs/trip-tb1.log"))
         (pid-of (lambda ()
                   (let ((ls (filter (lambda (l) (starts? l "trip-ros2: tb1 trip "))
                                     (read-lines log))))
                     (and (pair? ls) (string->number (last (words (last ls))))))))
         (first (pid-of)))
    (kill first signal/kill)
    (test-assert "the lab starts it again"
      (wait-until 40 (lambda () (let ((p (pid-of))) (and p (not (= p first)))))))
    (wait-until 40 (lambda () (= 2 (length (filter (lambda (l) (equal? l "trip-ros2: ready"))
                                                    (read-lines log))))))
    (test-assert "and the address space's trip client reconnects"
      (let ((p (remote-apply (uid->aspace 'tb1) (lab-proc 'pose-now))))
        (< (sqrt (+ (square (- (car p) 1000)) (square (- (cadr p) 500)))) 20)))))

(test-group "wheels that jam: stalled, with its odometry still coming"
  (let ((log (in-dir "logs/trip-tb2.log")))
    (kill tb2-robot 12)                 ; SIGUSR2: its wheels jam
    (test "goto-xy ends in trip's stalled error" "trip: tb2: goto-xy: the base is blocked"
          (remote-apply (uid->aspace 'tb2) (lab-proc 'try-goto) 1500 1000))
    (test-assert "and the trip server's log says why: not moved, on the robot's clock"
      (text-contains? (file-text log) "tb2: stalled in goto: not moved for"))
    (kill tb2-robot 12)                 ; freed again
    (test "freed, it drives there" 'arrived
          (remote-apply (uid->aspace 'tb2) (lab-proc 'try-goto) 0 1000))))

;; Where tb2's odometry says it is, within 20 mm of (x y).
(define (tb2-near? x y)
  (let ((p (remote-apply (uid->aspace 'tb2) (lab-proc 'pose-now))))
    (< (sqrt (+ (square (- (car p) x)) (square (- (cadr p) y)))) 20)))

(test-group "odometry that comes late: goto-xy still ends at its point"
  (kill tb2-robot 1)                    ; SIGHUP: odometry 0.1 s of every second
  (test "in bursts, a goto ends" 'arrived
        (parameterize ((remote-timeout 60))
          (remote-apply (uid->aspace 'tb2) (lab-proc 'try-goto) 1200 1000)))
  (kill tb2-robot 1)                    ; steady again
  (test-assert "at its point, not hunting round it" (tb2-near? 1200 1000))
  ;; Stopped for 2 s while it drives, the robot then makes up the time at
  ;; its last velocity, as a driver that went quiet and carried on.
  (let ((go (make-thread
             (lambda ()
               (parameterize ((remote-timeout 60))
                 (remote-apply (uid->aspace 'tb2) (lab-proc 'try-goto) -1200 1000))))))
    (thread-start! go)
    (thread-sleep! 4.5)
    (kill tb2-robot 19)                 ; SIGSTOP
    (thread-sleep! 2)
    (kill tb2-robot 18)                 ; SIGCONT
    (test "driven on blind for 2 s, a goto ends" 'arrived (thread-join! go))
    (test-assert "at its point" (tb2-near? -1200 1000))))

(test-group "odometry that stops: stalled, the robot lost, the component moves"
  (let ((t (start-task 'drive 1 (list '((mobile) ()))
                       (list (metric-by (lambda (uid) (if (eq? uid 'tb1) 0 1))))
                       (list (lab-proc 'drive-far)) '(1) '(#t))))
    (wait-until 20 (lambda () (eq? (car (status-state (car (task-status t)))) 'running)))
    (thread-sleep! 0.3)
    (kill tb1-robot 10)                 ; SIGUSR1: its odometry stops
    (let* ((r (task-wait t 90))
           (a (car (status-attempts (car (task-status t))))))
      (test "the component moves to tb2, which drives there" '(tb2) r)
      (test "tb1 is recorded as lost" '(tb1 lost) (list (car a) (cadr a)))
      (test-assert "for its base, which trip said stalled"
        (text-contains? (car (cddr a)) "stalled"))
      (test-assert "and its trip server's log says why"
        (text-contains? (file-text (in-dir "logs/trip-tb1.log"))
                        "tb1: stalled in goto: no odometry on /tb1/odom")))))

;; What the shell command prints, every line.
(define (shell-output command)
  (let ((out (in-dir "shell.out")))
    (if (file-exists? out) (delete-file out))
    (reap! (start-process! (list "/bin/sh" "-c" command) out))
    (file-text out)))

(test-group "every ROS 2 process on loopback alone"
  (let* ((pids (filter-map
                (lambda (file)
                  (let ((ls (filter (lambda (l) (starts? l "trip-ros2: ")) (read-lines file))))
                    (and (pair? ls) (string->number (last (words (car ls)))))))
                (list (in-dir "logs/trip-tb2.log"))))
         (env (lambda (pid)
                (shell-output (string-append "tr '\\0' '\\n' </proc/"
                                             (number->string pid) "/environ"))))
         (sockets (shell-output
                   (string-append "ss -Huanp | grep -E 'pid=("
                                  (fold (lambda (p acc) (string-append acc "|"
                                                                       (number->string p)))
                                        (number->string tb1-robot) (cons tb2-robot pids))
                                  "),'"))))
    (test-assert "the trip server runs with ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST"
      (text-contains? (env (car pids)) "ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST"))
    (test-assert "and the loopback profile"
      (text-contains? (env (car pids)) "robot/ros2/loopback.xml"))
    (test-assert "and the lab's domain"
      (text-contains? (env (car pids))
                      (string-append "ROS_DOMAIN_ID="
                                     (number->string (modulo (quotient (test-lab-port-base lab) 200) 102)))))
    (test-assert "DDS sockets found" (> (string-length sockets) 0))
    (test "every socket that receives on a port of the domain is on 127.0.0.1" '()
          (filter (lambda (line)
                    (let* ((local (list-ref (words line) 3))
                           (port (string->number (last (split-colon local))))
                           (d (modulo (quotient (test-lab-port-base lab) 200) 102))
                           (low (+ 7400 (* 250 d))))
                      (and port (<= low port (+ low 249))
                           (not (starts? local "127.0.0.1:")))))
                  (text-lines sockets)))
    (test "no socket joins a multicast group or talks to another host" '()
          (filter (lambda (line)
                    (let ((w (words line)))
                      (or (starts? (list-ref w 3) "239.")
                          (not (or (starts? (list-ref w 4) "0.0.0.0:")
                                   (starts? (list-ref w 4) "127.")
                                   (starts? (list-ref w 4) "*"))))))
                  (text-lines sockets)))))

(stop-process! lab-pid)

;; A lab of one robot, whose lab says twist where the robot wants
;; TwistStamped; then one whose robot never appears.  What `murdoch lab`
;; says; start is called with the lab's port base first.
(define (lab-output clauses name start)
  (let* ((l (make-test-lab clauses))
         (out (string-append (test-lab-directory l) "/" name ".out"))
         (robot (start (number->string (test-lab-port-base l))))
         (pid (start-process! (list (tool-path "bin/murdoch") "lab" (test-lab-file l)) out)))
    (wait-until 60 (lambda () (text-contains? (file-text out) "stopping the lab")))
    (reap! pid)
    (if robot (stop-process! robot))
    (let ((text (file-text out)))
      (remove-test-lab! l)
      text)))

(test-group "a simulated robot and a ROS 2 robot in one lab"
  (let* ((l (make-test-lab '((aspace b1 (robot (pose 0 0 0)))
                             (aspace tb3 (robot (pose 0 1000 0) (ros2 (namespace "/tb3")))))))
         (lbase (number->string (test-lab-port-base l)))
         (dir (test-lab-directory l))
         (robot (start-process! (list (tool-path "tools/ros2-env") lbase "python3"
                                      (tool-path "tests/ros2/unicycle.py") "--namespace" "/tb3")
                                (string-append dir "/unicycle.log")))
         (pid (start-murdoch-lab! (list (test-lab-file l)) (string-append dir "/lab.out")))
         (who (lambda (i)
                (let* ((c (trip-connect "127.0.0.1" (+ (test-lab-port-base l) 100 i)))
                       (w (trip-request c 'who)))
                  (trip-close c)
                  w))))
    (test "the simulator serves the B14 at its trip port" '("b1" "b14-sim") (who 0))
    (test "and the ROS 2 robot's own server its own, the simulator none for it"
          '("tb3" "ros2") (who 1))
    (stop-process! pid)
    (stop-process! robot)
    (remove-test-lab! l)))

(test-group "a cmd_vel of the wrong type: one clear error naming both"
  (let ((text (lab-output `((aspace tb2 (robot (ros2 (namespace "/tb2") (cmd-vel twist)
                                                     (appear-timeout 30)))))
                          "mismatch"
                          (lambda (base)
                            (let ((log (in-dir "unicycle-mismatch.log")))
                              (let ((pid (start-process!
                                          (list (tool-path "tools/ros2-env") base "python3"
                                                (tool-path "tests/ros2/unicycle.py")
                                                "--namespace" "/tb2" "--cmd-vel" "stamped")
                                          log)))
                                (wait-until 30 (lambda () (text-contains? (file-text log)
                                                                          "unicycle: ready")))
                                pid))))))
    (test-assert "it names the robot's type and the lab's"
      (and (text-contains? text "the robot subscribes geometry_msgs/msg/TwistStamped")
           (text-contains? text "publish geometry_msgs/msg/Twist")))
    (test-assert "and what to write" (text-contains? text "write (cmd-vel stamped)"))
    (test "once" 1 (length (filter (lambda (l) (text-contains? l "the robot subscribes"))
                                   (text-lines text))))
    (test-assert "and the lab stops" (text-contains? text "stopping the lab"))))

(test-group "a robot that never appears: the lab names it and the topic"
  (let ((text (lab-output '((aspace ghost (robot (ros2 (namespace "/ghost")
                                                       (appear-timeout 2)))))
                          "ghost" (lambda (base) #f))))
    (test-assert "the robot, and the topic it waited for"
      (and (text-contains? text "the robot ghost did not appear")
           (text-contains? text "/ghost/cmd_vel")))
    (test-assert "and the lab stops" (text-contains? text "stopping the lab"))))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
