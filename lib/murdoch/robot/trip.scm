;;;; The MOVER robot primitives, spoken over trip (docs/trip-protocol.md).
;;;
;;; One connection a robot, shared by the address space's threads: a
;;; request is sent under its lock, and the reader thread hands each reply
;;; to its tag's mailbox, so no request holds the connection while it
;;; waits.  A motion ends with `base await', answered when it is over; an
;;; abandoned mover (code/abandon.scm) is woken and stops the robot.
;;; Devices open on first use, or all with (im), as MOVER's did.

;;> Seconds to wait for any reply (the lab's trip-timeout, for the process's one robot).
(define trip-timeout (make-parameter (lab-default 'trip-timeout)))

;;> Seconds a \scheme{goto-xy} or \scheme{rotate} may take before it is stopped (the lab's).
(define trip-motion-timeout (make-parameter (lab-default 'trip-motion-timeout)))

;;> The connection the primitives use: #f on a workstation.  Global, as a
;;> process drives one robot: set it with \scheme{set-current-robot!}.
(define current-robot (make-parameter #f))

(define (set-current-robot! c) (current-robot c))

;;; Errors

(define (trip-error robot command code text)
  (raise (make-exception 'trip-error
                         (string-append "trip: " robot ": " command ": " text)
                         (list robot command code text) #f #f)))

;;> True for the errors this library raises.
(define (trip-error? e)
  (and (exception? e) (eq? (exception-kind e) 'trip-error)))

(define (trip-error-robot e) (car (exception-irritants e)))
;;> The protocol's error code as a symbol: held, not-open, args, timeout ...
(define (trip-error-code e) (string->symbol (list-ref (exception-irritants e) 2)))
(define (trip-error-text e) (list-ref (exception-irritants e) 3))

;;; Framing

(define stx 2)
(define etx 3)
(define dle 16)
(define max-reply 65536)

(define (special? b) (or (= b stx) (= b etx) (= b dle)))

(define (write-frame! payload out)
  (let ((bytes (string->utf8 payload)))
    (write-u8 stx out)
    (do ((i 0 (+ i 1))) ((= i (bytevector-length bytes)))
      (let ((b (bytevector-u8-ref bytes i)))
        (if (special? b)
            (begin (write-u8 dle out) (write-u8 (bitwise-xor b #x40) out))
            (write-u8 b out))))
    (write-u8 etx out)
    (flush-output-port out)))

;; The next byte or an eof object, waiting on the socket (port-wait!).
(define (next-byte in)
  (if (u8-ready? in)
      (read-u8 in)
      (begin (port-wait! in 3600) (next-byte in))))

;; The next whole frame's payload as a string, or an eof object.
(define (read-frame in)
  (let outside ()
    (let ((b (next-byte in)))
      (cond
       ((eof-object? b) b)
       ((not (= b stx)) (outside))
       (else
        (let inside ((acc (open-output-bytevector)) (n 0))
          (let ((b (next-byte in)))
            (cond
             ((eof-object? b) b)
             ((= b etx) (utf8->string (get-output-bytevector acc)))
             ((or (= b stx) (> n max-reply)) (outside))
             ((= b dle)
              (let ((c (next-byte in)))
                (cond
                 ((eof-object? c) c)
                 ((special? (bitwise-xor c #x40))
                  (write-u8 (bitwise-xor c #x40) acc)
                  (inside acc (+ n 1)))
                 (else (outside)))))
             (else (write-u8 b acc) (inside acc (+ n 1)))))))))))

;;; Connections

(define-record-type trip-connection
  (make-trip-connection host port in out lock waiting opened)
  trip-connection?
  (host trip-connection-host)
  (port trip-connection-port)
  (in trip-connection-in trip-connection-in-set!)
  (out trip-connection-out trip-connection-out-set!)
  (lock trip-connection-lock)              ; held to send, and for waiting
  (waiting trip-connection-waiting)        ; tag -> the mailbox of its request
  (opened trip-connection-opened trip-connection-opened-set!)
  (name trip-connection-name trip-connection-name-set!)
  (tag trip-connection-tag trip-connection-tag-set!)       ; the last sent
  (open? trip-connection-open? trip-connection-open?-set!)
  (goal trip-connection-goal trip-connection-goal-set!)    ; goto-xy's (x y)
  (lost? trip-connection-lost? trip-connection-lost?-set!) ; ended by the server
  (relock trip-connection-relock trip-connection-relock-set!))  ; held to reconnect

(define (robot-name c)
  (or (trip-connection-name c)
      (string-append (trip-connection-host c) ":"
                     (number->string (trip-connection-port c)))))

;;> Connects to the trip server of one robot and returns the connection.
(define (trip-connect host port)
  (let ((io (open-connection host port (trip-timeout))))
    (if (string? io)
        (trip-error (string-append host ":" (number->string port)) "connect"
                    "closed" (string-append "cannot connect: " io)))
    (let ((c (make-trip-connection host port (car io) (cadr io)
                                   (make-mutex 'trip) (make-hash-table eqv?) '())))
      (trip-connection-name-set! c #f)
      (trip-connection-tag-set! c 0)
      (trip-connection-open?-set! c #t)
      (trip-connection-goal-set! c #f)
      (trip-connection-lost?-set! c #f)
      (trip-connection-relock-set! c (make-mutex 'trip-reconnect))
      (thread-start! (make-logged-thread (lambda () (read-replies c)) 'trip-replies))
      (guard (e (#t (trip-close c) (raise e)))
        (trip-connection-name-set! c (car (request c "who"))))
      c)))

;;> Closes the connection; the server frees every device it held.
(define (trip-close c)
  (with-lock (trip-connection-lock c) (lambda () (shut! c))))

;; Close the socket once, under the lock, lest its number be another's.
(define (shut! c)
  (when (trip-connection-open? c)
    (trip-connection-open?-set! c #f)
    (guard (e (#t #f)) (close-input-port (trip-connection-in c)))
    (guard (e (#t #f)) (close-output-port (trip-connection-out c)))))

;; The connection's reader: each reply to its request's mailbox, until the end.
(define (read-replies c)
  (let ((frame (guard (e (#t (eof-object))) (read-frame (trip-connection-in c)))))
    (if (eof-object? frame)
        (for-each (lambda (mb) (mailbox-put! mb 'lost)) (close-for-good! c))
        (let* ((reply (split-words frame))
               (tag (and (pair? reply) (string->number (car reply))))
               (mb (and tag (take-waiting! c tag))))
          (if mb (mailbox-put! mb reply))
          (read-replies c)))))

;; The mailbox waiting for tag's reply, taken, or #f (tag 0, or gave up).
(define (take-waiting! c tag)
  (with-lock (trip-connection-lock c)
    (lambda () (take-mailbox! (trip-connection-waiting c) tag))))

;; Close c and take the mailboxes still waiting; the next request connects again.
(define (close-for-good! c)
  (with-lock (trip-connection-lock c)
    (lambda ()
      (if (trip-connection-open? c) (trip-connection-lost?-set! c #t))
      (shut! c)
      (take-all-mailboxes! (trip-connection-waiting c)))))

;; A connection the server ended (a restarted trip server) connects again,
;; once, and reopens its devices; a server still away is the error closed.
(define (reconnect! c command)
  (with-lock (trip-connection-relock c)
    (lambda ()
      (when (and (trip-connection-lost? c) (not (trip-connection-open? c)))
        (let ((io (open-connection (trip-connection-host c) (trip-connection-port c)
                                   (trip-timeout)))
              (devices (reverse (trip-connection-opened c))))
          (if (string? io)
              (trip-error (robot-name c) command "closed"
                          (string-append "connection lost, and cannot connect again: " io)))
          (with-lock (trip-connection-lock c)
            (lambda ()
              (trip-connection-in-set! c (car io))
              (trip-connection-out-set! c (cadr io))
              (trip-connection-lost?-set! c #f)
              (trip-connection-open?-set! c #t)
              (trip-connection-opened-set! c '())))
          (thread-start! (make-logged-thread (lambda () (read-replies c)) 'trip-replies))
          (for-each (lambda (d) (open-device! c d)) devices))))))

;;> The words of \var{s}, separated by spaces.
(define (split-words s)
  (let loop ((i 0) (start 0) (acc '()))
    (define (word) (if (= start i) acc (cons (substring s start i) acc)))
    (cond
     ((= i (string-length s)) (reverse (word)))
     ((char=? (string-ref s i) #\space) (loop (+ i 1) (+ i 1) (word)))
     (else (loop (+ i 1) start acc)))))

(define (join words)
  (if (null? words)
      ""
      (fold-left (lambda (acc w) (string-append acc " " w)) (car words) (cdr words))))

(define (fold-left f acc ls)
  (if (null? ls) acc (fold-left f (f acc (car ls)) (cdr ls))))

(define (->word x)
  (cond ((string? x) x)
        ((symbol? x) (symbol->string x))
        ((and (number? x) (exact? x)) (number->string x))
        ((number? x) (number->string (/ (round (* x 1000)) 1000.)))
        ((boolean? x) (if x "1" "0"))
        (else (error "not a trip argument" x))))

(define (reply-value w) (or (string->number w) w))

;; Sends one request and returns its ok reply's values, or raises a trip
;; error (err reply, lost connection, timeout, abandoned call).
(define (request c . words)
  (let ((command (join (map ->word words))))
    (exchange c command (+ (monotonic-seconds) (trip-timeout))
              (lambda ()
                (trip-error (robot-name c) command "timeout"
                            (string-append "no reply within "
                                           (number->string (trip-timeout)) " s"))))))

;; Sends command and returns its reply's values by deadline, else
;; (too-late); waits in a mailbox, woken should its caller give up.
(define (exchange c command deadline too-late)
  (let ((mb (make-mailbox)))
    (define (fail code text) (trip-error (robot-name c) command code text))
    (with-wake-on-abandon
     (lambda () (mailbox-put! mb 'abandoned))
     (lambda ()
       (check-not-abandoned command)
       (if (trip-connection-lost? c) (reconnect! c command))
       (let* ((tag (send! c command mb fail))
              (reply (mailbox-take mb deadline (lambda () 'late))))
         ;; A late reply finds no mailbox and is dropped.
         (when (symbol? reply)
           (take-waiting! c tag))
         (case reply
           ((late) (too-late))
           ;; Marked when woken: the mark stays until the call is over.
           ((abandoned) (check-not-abandoned command))
           ((lost) (fail "closed" "connection lost"))
           (else (reply-values reply fail))))))))

;; Writes command under a new tag, for mailbox mb; answers the tag.
(define (send! c command mb fail)
  (with-lock (trip-connection-lock c)
    (lambda ()
      (if (not (trip-connection-open? c))
          (fail "closed" "connection closed"))
      (let ((tag (+ 1 (modulo (trip-connection-tag c) 999999998))))
        (trip-connection-tag-set! c tag)
        (hash-table-set! (trip-connection-waiting c) tag mb)
        (guard (e (#t (shut! c) (fail "closed" "cannot send")))
          (write-frame! (string-append (number->string tag) " " command)
                        (trip-connection-out c)))
        tag))))

;; The values of an ok reply, (TAG ok VALUE ...); an err reply raises.
(define (reply-values reply fail)
  (if (and (pair? (cdr reply)) (equal? (cadr reply) "ok"))
      (map reply-value (cddr reply))
      (fail (if (pair? (cddr reply)) (car (cddr reply)) "protocol")
            (join (if (pair? (cddr reply)) (cdr (cddr reply)) reply)))))

;;> One raw request on \var{c}, words joined with spaces: \scheme{(trip-request c 'buttons 'press 2)}.
(define trip-request request)

;;; Devices

(define devices '(base sonar ir bumpers skirt buttons lights speech battery fiducial))

(define (robot)
  (or (current-robot)
      (error "no robot: this address space has no trip connection")))

(define (open-device! c device)
  (if (not (memq device (trip-connection-opened c)))
      (begin (request c "open" device)
             (trip-connection-opened-set! c (cons device (trip-connection-opened c))))))

;; A device command to the current robot, opening the device first.
(define (device device . words)
  (let ((c (robot)))
    (open-device! c device)
    (apply request c device words)))

;;> MOVER's initialisation: opens every device of the current robot, so
;;> that one held elsewhere shows now, not mid-task.
(define (im)
  (for-each (lambda (d)
              (guard (e ((and (trip-error? e) (eq? (trip-error-code e) 'unknown)) #f))
                (open-device! (robot) d)))
            devices)
  #t)

;;; Motion

;; Waits for the motion's end (base await): the final pose.  Stopped past
;; (trip-motion-timeout), or when the caller gave up.
(define (await-motion what)
  (let* ((c (robot))
         (end (guard (e ((abandoned-error? e)
                         (despite-abandonment stop-base)
                         (check-not-abandoned what)))
                (exchange c "base await" (+ (monotonic-seconds) (trip-motion-timeout))
                          (lambda ()
                            (stop-base)
                            (trip-error (robot-name c) what "timeout"
                                        "motion took too long"))))))
    (if (= 1 (list-ref end 3))
        (trip-error (robot-name c) what "stalled" "the base is blocked"))
    (list (car end) (cadr end) (car (cddr end)) 0)))

;;> Drives to \var{xy}, (x y) in mm of the odometry frame, facing it first; the pose reached.
(define (goto-xy xy)
  (let ((c (robot)))
    (dynamic-wind
     (lambda () (trip-connection-goal-set! c (list (car xy) (cadr xy))))
     (lambda ()
       (device 'base "goto" (car xy) (cadr xy))
       (await-motion "goto-xy"))
     (lambda () (trip-connection-goal-set! c #f)))))

;;> Where the robot's goto-xy is driving it, (x y), or #f (for the view).
(define (goto-goal)
  (let ((c (current-robot)))
    (and c (trip-connection-goal c))))

;;> \scheme{(rotate 'by degrees)} turns in place (counter-clockwise positive);
;;> \scheme{(rotate 'to heading)} turns to a heading.
(define (rotate how degrees)
  (let ((by (case how
              ((by) degrees)
              ((to) (angle-to-heading degrees))
              (else (error "rotate takes 'by or 'to" how)))))
    (device 'base "rotate" by)
    (await-motion "rotate")))

;;> Moves \var{mm} millimetres along the heading (backwards when negative).
(define (translate mm)
  (device 'base "translate" mm)
  (await-motion "translate"))

;;> The turn, in (-180, 180], that brings the robot to \var{heading}.
(define (angle-to-heading heading)
  (let ((a (- heading (car (cddr (reckon))))))
    (let ((w (- a (* 360 (round (/ a 360))))))
      (if (<= w -180) (+ w 360) w))))

;;> The robot's own clock, seconds: the simulator's time, which slips when
;;> the machine cannot keep up, so a robot timing by it keeps its world's pace.
(define (robot-time) (/ (car (request (robot) "time")) 1000.))

;;> Translation (mm/s) and rotation (deg/s) velocities, until changed.
(define (set-velocity tv rv) (device 'base "vel" tv rv) #t)
;;> Stops the base at once: both velocities zero.
(define (stop-base) (device 'base "stop") #t)

;;> The odometry pose: (x y theta 0), millimetres and degrees.
(define (reckon)
  (append (device 'base "reckon") '(0)))

;;> Sets the odometry's position to (\var{x} \var{y}), millimetres.
(define (set-reckon-position! x y) (device 'base "set-position" x y) #t)
;;> Sets the odometry's heading to \var{theta}, degrees.
(define (set-reckon-heading! theta) (device 'base "set-heading" theta) #t)

;;; Sensors and the rest

;;> Starts the sonar ring firing.
(define (sonar-start) (device 'sonar "start") #t)
;;> Stops the sonar ring.
(define (sonar-stop) (device 'sonar "stop") #t)
;;> The 16 sonar ranges in mm, sonar 0 ahead, counter-clockwise; the
;;> latest, kept after \scheme{sonar-stop}.
(define (sonar-read) (device 'sonar "read"))
;;> The 16 infrared ranges in mm; the longest means nothing seen.
(define (ir-read) (device 'ir "read"))
;;> The 12 front bumpers: 1 for each one pressed, else 0.
(define (bumpers-read) (device 'bumpers "read"))
;;> The bump skirt's 6 segments round the robot: 1 for each pressed, else 0.
(define (skirt-read) (device 'skirt "read"))
;;> The buttons pressed since the last call, as four 0/1.
(define (buttons-read) (device 'buttons "read"))

;;> Sets the four LEDs from a list or four 0/1 or #f/#t; with none, answers them.
(define (lights . which)
  (let ((ls (if (and (pair? which) (list? (car which))) (car which) which)))
    (if (null? ls)
        (device 'lights "read")
        (begin (apply device 'lights "set"
                      (map (lambda (x) (if (memv x '(#f 0)) 0 1)) ls))
               #t))))

;;> Says the things given, displayed and joined.
(define (say . things)
  (device 'speech "say"
          (join (map (lambda (x)
                       (if (string? x)
                           x
                           (call-with-output-string (lambda (out) (write x out)))))
                     things)))
  #t)

;;> The boxes the fiducial finder sees (docs/trip-protocol.md), nearest
;;> first, as (ID RANGE BEARING ORIENTATION), in mm and degrees; () for none.
(define (fiducials)
  (let loop ((words (cdr (device 'fiducial "read"))) (seen '()))
    (if (null? words)
        (reverse seen)
        (loop (list-tail words 4)
              (cons (list (exact (car words)) (exact (cadr words)) (car (cddr words))
                          (cadr (cddr words)))
                    seen)))))

;;> The ID, the box's index among the lab's boxes, of \var{f}, one of fiducials'.
(define (fiducial-id f) (car f))

;;> The RANGE in mm of \var{f}, one of fiducials'.
(define (fiducial-range f) (cadr f))

;;> The BEARING in degrees of \var{f}, one of fiducials'.
(define (fiducial-bearing f) (car (cddr f)))

;;> The ORIENTATION in degrees of \var{f}, one of fiducials'.
(define (fiducial-orientation f) (cadr (cddr f)))

;;> The battery in tenths of a volt, an integer (136 for 13.6 V), the thesis's unit.
(define (battery-voltage)
  (exact (round (* 10 (car (device 'battery "read"))))))

;;> True when the robot is tethered (on its charger's cable).
(define (tethered?) (= 1 (cadr (device 'battery "read"))))
;;> Tethers the robot (\var{on?} true) or frees it, in the simulator.
(define (set-tether! on?) (device 'battery "tether" on?) #t)

;;; safe.scm: answers any address space can give

;;> \scheme{im} on a robot, #t elsewhere.
(define (safe-im)
  (if (current-robot) (im) #t))

;;> The battery on a robot; elsewhere, or with no reading, 140: enough to count as charging.
(define (safe-battery-voltage)
  (if (current-robot)
      (guard (e ((and (trip-error? e) (eq? (trip-error-code e) 'unknown)) 140))
        (battery-voltage))
      140))

;;> Where a workstation says it is, (x y heading), or #f.  Global, as a
;;> process is one machine: set it once, \scheme{(workstation-position '(-1524 -2743.2 90))}.
(define workstation-position (make-parameter #f))

;;> \scheme{reckon} on a robot; on a workstation its fixed \var{position}
;;> (default \scheme{(workstation-position)}) as (x y heading 0), or #f.
(define (safe-reckon . position)
  (let ((p (if (pair? position) (car position) (workstation-position))))
    (cond ((current-robot) (reckon))
          (p (list (car p) (cadr p) (car (cddr p)) 0))
          (else #f))))
